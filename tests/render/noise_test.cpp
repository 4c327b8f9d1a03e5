// The render's own noise estimate (docs/render.md, "Noise"), stopping on it, and photons that carry
// their own wavelengths.

#include <gtest/gtest.h>

#include <vector>

#include "render_test_util.h"
#include "src/core/color.h"
#include "src/core/image_error.h"
#include "src/core/progress.h"
#include "src/render/bricks/procedural_meshes.h"

namespace nave::render {
namespace {

using testing::ClutterMesh;
using testing::MeanY;
using testing::Render;

class NoiseTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

// Sun and sky on a floor, balls and a box: noisy where the sky and the bounces are.
std::string ClutterConfig(const char* mode, uint64_t seed, int spp, int iterations,
                          double noise_target) {
    return testing::ClutterScene(48, 36) + fmt::format(R"(
[render]
mode = "{}"
spp = {}
iterations = {}
photons_per_iteration = 20000
initial_radius_m = 0.3
noise_target = {}
seed = {}
)",
                                                       mode, spp, iterations, noise_target, seed);
}

std::vector<float> Luminance(const Film& film) {
    std::vector<float> y(film.pixel_count());
    for (size_t p = 0; p < y.size(); ++p) y[p] = float(film.PixelXYZ(uint32_t(p)).y);
    return y;
}

// Two renders that differ only in the seed measure the error of one (PairRelMse); each render's own
// estimate, from the halves of its samples, must tell the same within the estimates' own spread.
void ExpectEstimateAgreesWithTwoSeeds(const char* mode) {
    const std::vector<std::string> names = {"floor", "ball", "chrome"};
    auto a = Render(ClutterMesh(), names, ClutterConfig(mode, 1, 8, 8, 0), 2);
    auto b = Render(ClutterMesh(), names, ClutterConfig(mode, 2, 8, 8, 0), 2);
    ASSERT_TRUE(a && b);
    const double measured = PairRelMse(Luminance(*a->film), Luminance(*b->film));
    EXPECT_GT(measured, 1e-4);  // noisy enough to measure
    for (const auto* t : {a.get(), b.get()}) {
        EXPECT_GT(t->stats.noise_relmse, 0.6 * measured) << mode << ", measured " << measured;
        EXPECT_LT(t->stats.noise_relmse, 1.6 * measured) << mode << ", measured " << measured;
    }
}

TEST_F(NoiseTest, PathEstimateAgreesWithTwoSeeds) { ExpectEstimateAgreesWithTwoSeeds("path"); }

TEST_F(NoiseTest, PhotonEstimateAgreesWithTwoSeeds) { ExpectEstimateAgreesWithTwoSeeds("photon"); }

TEST_F(NoiseTest, OnePassHasNoEstimate) {
    auto t =
        Render(ClutterMesh(), {"floor", "ball", "chrome"}, ClutterConfig("path", 1, 1, 1, 0), 1);
    ASSERT_TRUE(t);
    EXPECT_TRUE(std::isnan(t->stats.noise_relmse));
}

// relMSE falls as 1 / samples: the estimate after 16 passes, taken as the target, is reached after
// about 16 passes of a render allowed 256, and the render says so.
void ExpectTargetStopsEarly(const char* mode) {
    const std::vector<std::string> names = {"floor", "ball", "chrome"};
    const bool photon = std::string(mode) == "photon";
    auto sixteen = Render(ClutterMesh(), names, ClutterConfig(mode, 5, 16, 16, 0), 2);
    ASSERT_TRUE(sixteen);
    const double target = sixteen->stats.noise_relmse;
    ASSERT_GT(target, 0);
    auto stopped = Render(ClutterMesh(), names, ClutterConfig(mode, 6, 256, 256, target), 2);
    ASSERT_TRUE(stopped);
    const int done = photon ? stopped->stats.iterations : stopped->stats.samples_per_pixel;
    EXPECT_GE(done, 8) << mode;
    EXPECT_LE(done, 40) << mode;
    // The final estimate, after the last pass has finished, is near the target (it stopped on it).
    EXPECT_LT(stopped->stats.noise_relmse, 1.4 * target) << mode;
}

TEST_F(NoiseTest, TargetStopsThePassesEarly) { ExpectTargetStopsEarly("path"); }

TEST_F(NoiseTest, TargetStopsTheIterationsEarly) { ExpectTargetStopsEarly("photon"); }

TEST_F(NoiseTest, NoiseTargetIsAConfigKey) {
    auto config = ParseSceneConfig(ClutterConfig("path", 1, 1, 1, -1), "bad.toml");
    ASSERT_FALSE(config.ok());
    EXPECT_NE(config.status().message().find("noise_target"), std::string::npos)
        << config.status().ToString();
}

// Every photon carries its own wavelengths, so one iteration already averages many: inside the
// white furnace (flat reflectance 0.5, flat emission 0.5) one iteration's image is white (the
// equal-energy point x = y = 1/3), as it must be whatever wavelengths were drawn. With one set of
// four wavelengths for the whole iteration, its colour would be that of four random wavelengths.
TEST_F(NoiseTest, OnePhotonIterationOfAGreyFurnaceIsWhite) {
    store::BrickMesh m;
    AppendSphere(&m, {0, 0, 0}, 1.0f, 24, 48, 0, /*inward=*/true);
    auto t = Render(m, {"shell"}, R"(
[camera]
position = [0.1, 0.05, 0.0]
look_at = [1, 0.2, 0.1]
fov_deg = 90
resolution = [32, 24]
[materials.shell]
reflectance = 0.5
emission = 0.5
[render]
mode = "photon"
iterations = 1
photons_per_iteration = 200000
initial_radius_m = 0.3
max_depth = 64
seed = 9
)",
                    1);
    ASSERT_TRUE(t);
    Vec3d sum;
    for (size_t p = 0; p < t->film->pixel_count(); ++p) sum += t->film->PixelXYZ(uint32_t(p));
    const Chromaticity xy = XYZToChromaticity(sum);
    EXPECT_NEAR(xy.x, 1.0 / 3, 0.004);
    EXPECT_NEAR(xy.y, 1.0 / 3, 0.004);
    EXPECT_NEAR(MeanY(*t->film), 1.0, 0.05);
}

}  // namespace
}  // namespace nave::render
