// Sky next-event estimation through portals (render.sky_sampling = "portals"): a closed room lit only by a
// uniform sky through a window in its roof (render_test_util.h). Aiming sky samples at the window must give
// the same image in expectation as uniform directions (the estimator stays unbiased: MIS against BSDF sampling
// with the mixture pdf, Veach 1997) and less noise (most uniform directions hit the walls and roof). With
// max_depth 1 the test also catches paths that stop at the window instead of passing through it.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render_test_util.h"

namespace nave::render {
namespace {

const std::vector<std::string> kMaterials = {"floor", "wall", "window"};

constexpr const char* kConfig = R"(
[camera]
position = [0.0, -1.8, 1.5]
look_at = [0.0, 0.0, 0.0]
up = [0, 0, 1]
fov_deg = 70
resolution = [24, 24]
[sky]
radiance = 1.0
[materials.floor]
reflectance = 0.5
[materials.wall]
reflectance = 0.5
[materials.window]
type = "thin_dielectric"
eta = 1.5
portal = true
[render]
spp = 32
max_depth = 1
)";

struct Result {
    double mean = 0;   ///< mean luminance over the image
    double noise = 0;  ///< RMS of the per-pixel difference between two seeds, over sqrt(2)
    size_t pixels = 0;
};

Result RenderRoom(const std::string& sky_sampling) {
    std::vector<double> y[2];
    for (int seed = 0; seed < 2; ++seed) {
        const std::string config = std::string(kConfig) + "sky_sampling = \"" + sky_sampling + "\"\nseed = " +
                                   std::to_string(seed + 1) + "\n";
        auto t = testing::Render(testing::RoomWithRoofWindow(), kMaterials, config, 2);
        EXPECT_TRUE(t != nullptr);
        if (t == nullptr) return {};
        for (uint32_t p = 0; p < uint32_t(t->film->pixel_count()); ++p) y[seed].push_back(t->film->PixelXYZ(p).y);
    }
    Result r;
    r.pixels = y[0].size();
    double diff2 = 0;
    for (size_t p = 0; p < y[0].size(); ++p) {
        r.mean += (y[0][p] + y[1][p]) / 2;
        diff2 += (y[0][p] - y[1][p]) * (y[0][p] - y[1][p]);
    }
    r.mean /= double(r.pixels);
    r.noise = std::sqrt(diff2 / double(r.pixels) / 2);
    return r;
}

TEST(SkyPortals, SameImageInExpectationWithLessNoise) {
    const Result uniform = RenderRoom("uniform"), portals = RenderRoom("portals");
    ASSERT_GT(uniform.mean, 0);
    // Each mean averages 2 x pixels x 32 paths; their difference stays within a few standard errors.
    const double tolerance = 4 * std::hypot(uniform.noise, portals.noise) / std::sqrt(2.0 * double(uniform.pixels));
    EXPECT_NEAR(portals.mean, uniform.mean, tolerance) << "uniform noise " << uniform.noise << ", portals noise "
                                                      << portals.noise;
    EXPECT_LT(portals.noise, 0.5 * uniform.noise);
}

TEST(SkyPortals, PortalSamplingWithoutPortalsIsAnError) {
    std::string config = kConfig;
    config.replace(config.find("portal = true"), std::string("portal = true").size(), "");
    Status s;
    auto t = testing::Render(testing::RoomWithRoofWindow(), kMaterials, config + "sky_sampling = \"portals\"\n", 1,
                             0, &s);
    ASSERT_TRUE(t != nullptr);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("portal = true"), std::string::npos) << s.ToString();
}

}  // namespace
}  // namespace nave::render
