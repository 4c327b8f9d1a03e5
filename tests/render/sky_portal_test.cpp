// Sky next-event estimation through portals (render.sky_sampling = "portals"): a closed room lit
// only by a uniform sky through a window in its roof (render_test_util.h). Aiming sky samples at
// the window must give the same image in expectation as uniform directions (the estimator stays
// unbiased: MIS against BSDF sampling with the mixture pdf, Veach 1997) and less noise (most
// uniform directions hit the walls and roof). With max_depth 1 the test also catches paths that
// stop at the window instead of passing through it.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render_test_util.h"

namespace nave::render {
namespace {

const std::vector<std::string> kMaterials = {"floor", "wall", "window"};

std::string RoomConfig() {
    return testing::RoomWithRoofWindowScene() + R"(
[render]
spp = 32
max_depth = 1
)";
}

testing::SeedPair RenderRoom(const std::string& sky_sampling) {
    return testing::RenderSeedPair(testing::RoomWithRoofWindow(), kMaterials,
                                   RoomConfig() + "sky_sampling = \"" + sky_sampling + "\"", 2);
}

TEST(SkyPortals, SameImageInExpectationWithLessNoise) {
    const testing::SeedPair uniform = RenderRoom("uniform"), portals = RenderRoom("portals");
    ASSERT_GT(uniform.mean, 0);
    // Each mean averages 2 x pixels x 32 paths; their difference stays within a few standard
    // errors.
    const double tolerance =
        4 * std::hypot(uniform.noise, portals.noise) / std::sqrt(2.0 * double(uniform.pixels));
    EXPECT_NEAR(portals.mean, uniform.mean, tolerance)
        << "uniform noise " << uniform.noise << ", portals noise " << portals.noise;
    EXPECT_LT(portals.noise, 0.5 * uniform.noise);
}

// Photon mode with final gathering, its sky next-event estimation choosing the window the sky's
// photons taught each region (SkyWindows), and its gather guided by the bounced photons: the same
// room, now with indirect light (max_depth 4), agrees with path tracing through the portals.
TEST(SkyPortals, FinalGatherWithLearnedWindowsAgreesWithPathTracing) {
    const std::string deeper = [] {
        std::string c = RoomConfig();
        c.replace(c.find("max_depth = 1"), std::string("max_depth = 1").size(), "max_depth = 4");
        return c + "sky_sampling = \"portals\"\n";
    }();
    const testing::SeedPair path =
        testing::RenderSeedPair(testing::RoomWithRoofWindow(), kMaterials, deeper, 2);
    const testing::SeedPair photon = testing::RenderSeedPair(
        testing::RoomWithRoofWindow(), kMaterials,
        deeper +
            "mode = \"photon\"\nfinal_gather = true\nphoton_target = \"portals\"\n"
            "iterations = 24\nphotons_per_iteration = 20000\ninitial_radius_m = 0.2\n",
        2);
    ASSERT_GT(path.mean, 0);
    // Within the two renders' noise and the photon estimate's blur (a few percent at this radius).
    const double tolerance = 0.04 * path.mean + 4 * std::hypot(path.noise, photon.noise) /
                                                    std::sqrt(2.0 * double(path.pixels));
    EXPECT_NEAR(photon.mean, path.mean, tolerance)
        << "path noise " << path.noise << ", photon noise " << photon.noise;
}

// The camera's shadow rays toward the sky teach the windows too. The camera looks straight down
// at 2 cm of floor under the window, so that its 576 pixels fall in one or two regions (cells of
// 4 m / 64); with 12 photons an iteration, at most 3 of which record a window (fewer than
// SkyWindows::kMinPhotons), those regions have chosen their window after the first iteration only
// if the shadow rays taught them.
TEST(SkyPortals, TheCamerasShadowRaysTeachTheWindows) {
    auto t = testing::Render(testing::RoomWithRoofWindow(), kMaterials, R"(
[camera]
position = [0.3, 0.3, 1.0]
look_at = [0.3, 0.3, 0.0]
up = [0, 1, 0]
fov_deg = 1
resolution = [24, 24]
)" + testing::RoomWithRoofWindowSkyAndMaterials() + R"(
[render]
mode = "photon"
final_gather = true
sky_sampling = "portals"
photon_target = "portals"
iterations = 1
photons_per_iteration = 12
max_depth = 4
)",
                             2);
    ASSERT_TRUE(t != nullptr);
    EXPECT_GT(t->stats.sky_window_regions, 0u);
}

TEST(SkyPortals, PortalSamplingWithoutPortalsIsAnError) {
    std::string config = RoomConfig();
    config.replace(config.find("portal = true"), std::string("portal = true").size(), "");
    Status s;
    auto t = testing::Render(testing::RoomWithRoofWindow(), kMaterials,
                             config + "sky_sampling = \"portals\"\n", 1, 0, &s);
    ASSERT_TRUE(t != nullptr);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("portal = true"), std::string::npos) << s.ToString();
}

}  // namespace
}  // namespace nave::render
