// End-to-end renders of small in-memory scenes: furnace, analytic sun irradiance, brick-count and
// thread-count independence.

#include <gtest/gtest.h>

#include "core/color.h"
#include "core/progress.h"
#include "render/procedural_meshes.h"
#include "render_test_util.h"

namespace nave::render {
namespace {

using testing::MeanY;
using testing::Render;

class RenderTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

// White furnace: inside a closed sphere of albedo a whose surface emits Le, the radiance everywhere is
// Le / (1 - a) (the Neumann series of the rendering equation, Kajiya 1986, with constant L). With a = 0.5,
// Le = 0.5: L = 1, and a constant spectrum of 1 has Y = 1 (CIE normalisation of SampledToXYZ).
store::BrickMesh FurnaceMesh() {
    store::BrickMesh m;
    AppendSphere(&m, {0, 0, 0}, 1.0f, 24, 48, 0, /*inward=*/true);
    return m;
}
constexpr const char* kFurnace = R"(
[camera]
position = [0.1, 0.05, 0.0]
look_at = [1, 0.2, 0.1]
fov_deg = 90
resolution = [16, 12]
[materials.shell]
reflectance = 0.5
emission = 0.5
[render]
mode = "{}"
spp = 64
iterations = 12
photons_per_iteration = 60000
max_depth = 64
seed = 3
)";

TEST_F(RenderTest, WhiteFurnacePathTracing) {
    auto t = Render(FurnaceMesh(), {"shell"}, fmt::format(fmt::runtime(kFurnace), "path"), 1);
    ASSERT_TRUE(t);
    std::printf("furnace mean Y %.5f\n", MeanY(*t->film));
    EXPECT_NEAR(MeanY(*t->film), 1.0, 0.02);
}

TEST_F(RenderTest, WhiteFurnacePhotonMapping) {
    auto t = Render(FurnaceMesh(), {"shell"}, fmt::format(fmt::runtime(kFurnace), "photon"), 2);
    ASSERT_TRUE(t);
    std::printf("furnace mean Y %.5f\n", MeanY(*t->film));
    EXPECT_NEAR(MeanY(*t->film), 1.0, 0.02);
    EXPECT_GT(t->stats.photons, 0u);
}

// A diffuse plane of albedo R lit by the sun alone: L = R / pi * E, E = L_sun * Omega_sun * cos(zenith)
// (Lambert's cosine law; the disc's radiance is uniform, and cos varies by < 1e-4 across the disc).
TEST_F(RenderTest, SunOnDiffusePlaneMatchesCosineLaw) {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {50, 0, 0}, {0, 50, 0}, 4, 0);
    for (float elevation_deg : {90.f, 30.f}) {
        float e = elevation_deg * 3.14159265f / 180.f;
        std::string config = fmt::format(R"(
[camera]
position = [0, 0, 5]
look_at = [0.01, 0, 0]
fov_deg = 20
resolution = [8, 8]
[sun]
direction = [{}, 0, {}]
radiance = 1000.0
[materials.plane]
reflectance = 0.6
[render]
spp = 4
)",
                                         std::cos(e), std::sin(e));
        auto t = Render(m, {"plane"}, config, 1);
        ASSERT_TRUE(t);
        float cos_sun = std::cos(0.2666f * 3.14159265f / 180.f);
        double omega = 2 * 3.14159265 * (1 - cos_sun);
        double expected = 0.6 / 3.14159265 * 1000.0 * omega * std::sin(e);
        // Y of a constant spectrum equals its value; the estimate is exact up to the 4 wavelengths' pdf
        // weighting of a flat spectrum, which is exact.
        std::printf("sun plane %.5f expected %.5f\n", MeanY(*t->film), expected);
        EXPECT_NEAR(MeanY(*t->film), expected, 0.01 * expected) << "elevation " << elevation_deg;
    }
}

// The decomposition must not change the image: same seed, 1 brick vs 64 bricks vs other thread counts.
store::BrickMesh ClutterMesh() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 6, 0);
    AppendSphere(&m, {0.5f, 0.3f, 1.0f}, 0.8f, 16, 32, 1);
    AppendSphere(&m, {-1.5f, -1.0f, 0.6f}, 0.6f, 12, 24, 2);
    AppendBox(&m, Bounds3f({1.0f, -2.5f, 0.01f}, {2.5f, -1.2f, 1.8f}), 0);
    return m;
}
constexpr const char* kClutter = R"(
[camera]
position = [6, 5, 3.5]
look_at = [0, 0, 0.6]
fov_deg = 45
resolution = [32, 24]
[sun]
direction = [0.4, -0.5, 0.75]
[sky]
radiance = 0.05
[materials.floor]
reflectance = 0.7
[materials.ball]
reflectance = {{ wavelengths_nm = [400, 550, 700], values = [0.1, 0.5, 0.9] }}
[materials.chrome]
type = "conductor"
roughness = 0.2
[render]
mode = "{}"
spp = 4
iterations = 3
photons_per_iteration = 20000
seed = 11
)";

double MaxRelativeDifference(const Film& a, const Film& b) {
    double worst = 0;
    for (size_t p = 0; p < a.pixel_count(); ++p) {
        Vec3d x = a.PixelXYZ(uint32_t(p)), y = b.PixelXYZ(uint32_t(p));
        for (int c = 0; c < 3; ++c) {
            double d = std::abs(x[c] - y[c]) / std::max(1e-3, std::abs(x[c]) + std::abs(y[c]));
            worst = std::max(worst, d);
        }
    }
    return worst;
}

TEST_F(RenderTest, OneBrickAnd64BricksRenderTheSameImagePath) {
    std::string config = fmt::format(fmt::runtime(kClutter), "path");
    auto one = Render(ClutterMesh(), {"floor", "ball", "chrome"}, config, 1, 1);
    auto many = Render(ClutterMesh(), {"floor", "ball", "chrome"}, config, 4, 2);
    auto many_more_threads = Render(ClutterMesh(), {"floor", "ball", "chrome"}, config, 4, 4);
    ASSERT_TRUE(one && many && many_more_threads);
    EXPECT_GT(many->source->brick_count(), 30u);
    EXPECT_GT(many->stats.brick_moves, 0u);
    EXPECT_GT(MeanY(*one->film), 0.0);
    // Bound: the sums differ only by double summation order (relative ~1e-15 per add).
    EXPECT_LT(MaxRelativeDifference(*one->film, *many->film), 1e-9);
    EXPECT_LT(MaxRelativeDifference(*many->film, *many_more_threads->film), 1e-9);
}

TEST_F(RenderTest, OneBrickAnd64BricksRenderTheSameImagePhoton) {
    std::string config = fmt::format(fmt::runtime(kClutter), "photon");
    auto one = Render(ClutterMesh(), {"floor", "ball", "chrome"}, config, 1, 1);
    auto many = Render(ClutterMesh(), {"floor", "ball", "chrome"}, config, 4, 3);
    ASSERT_TRUE(one && many);
    EXPECT_GT(MeanY(*one->film), 0.0);
    // Photon deposits add floats atomically per pixel: summation order changes the float flux by ~1e-6.
    EXPECT_LT(MaxRelativeDifference(*one->film, *many->film), 1e-4);
}

TEST_F(RenderTest, MissingMaterialMappingNamesIt) {
    auto device = EmbreeDevice::Create();
    ASSERT_TRUE(device.ok());
    GridBricks grid = SplitIntoGridBricks(FurnaceMesh(), 1, 1, 1);
    store::MaterialRecord rec;
    rec.name = "glass_blue";
    MemoryBrickSource source(*device, grid.tree, grid.meshes, {rec});
    auto config = ParseSceneConfig("[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[materials.limestone]\n", "abbey.toml");
    ASSERT_TRUE(config.ok()) << config.status().ToString();
    auto scene = BuildRenderScene(*config, source);
    ASSERT_FALSE(scene.ok());
    EXPECT_NE(scene.status().message().find("glass_blue"), std::string::npos) << scene.status().message();
    EXPECT_NE(scene.status().message().find("abbey.toml"), std::string::npos) << scene.status().message();
}

}  // namespace
}  // namespace nave::render
