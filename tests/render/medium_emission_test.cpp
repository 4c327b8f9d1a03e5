// Media that emit light ([medium] emission, emission_grid, temperature_grid): the radiance of a
// glowing slab against the closed form of its emission and absorption, a glowing medium in the
// white furnace at equilibrium (Kirchhoff's law), and configs that cannot be rendered, named.

#include "src/render/scene/media/medium_emission.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render_test_util.h"
#include "src/core/progress.h"
#include "src/render/bricks/procedural_meshes.h"

namespace nave::render {
namespace {

using testing::MeanY;
using testing::Render;

class MediumEmissionTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

/// kLampConfig with more samples per pixel.
std::string LampConfig(int spp) {
    std::string config = testing::kLampConfig;
    config.replace(config.find("spp = 4"), 7, "spp = " + std::to_string(spp));
    return config;
}

// A slab 1 m thick of a pure absorber σa that emits Le, in front of the lamp (radiance 1): along
// the view, L = e^(-σa) 1 + ∫_0^1 σa Le e^(-σa s) ds = e^(-σa) + Le (1 - e^(-σa)) (the radiative
// transfer equation without scattering; Chandrasekhar 1960 §1.4).
TEST_F(MediumEmissionTest, AGlowingAbsorbingSlabAddsItsEmissionToWhatItDims) {
    const float sigma_a = 0.7f, le = 2.f;
    // The slab 1 m thick across the view, its emission given by `emission` (keys of [medium]).
    const auto slab = [&](const std::string& emission) {
        return Render(testing::LampMesh(), {"lamp"},
                      LampConfig(64) + fmt::format("[medium]\nbox_min = [1, -1, -1]\n"
                                                   "box_max = [2, 1, 1]\nsigma_a = {}\n{}\n",
                                                   sigma_a, emission),
                      2);
    };
    const auto t = slab(fmt::format("emission = {}", le));
    ASSERT_TRUE(t);
    const double expected = std::exp(-sigma_a) + le * (1 - std::exp(-sigma_a));
    EXPECT_NEAR(MeanY(*t->film), expected, 0.01 * expected);

    // emission_scale multiplies the emission: Le 1 times 2 is the same slab.
    const auto scaled = slab(fmt::format("emission = 1\nemission_scale = {}", le));
    ASSERT_TRUE(scaled);
    EXPECT_LT(testing::MaxRelativeDifference(*t->film, *scaled->film), 1e-6);
}

// The white furnace (radiance 1 everywhere) filled with a medium that absorbs, scatters and emits
// Le = 1: along any ray dL/ds = -σt L + σa Le + σs ∫ p L = 0 at L = 1, so the image stays at 1
// only if emission makes up for absorption exactly (Kirchhoff's law), scattering or not.
TEST_F(MediumEmissionTest, AGlowingMediumInTheWhiteFurnaceStaysAtOne) {
    const auto t = Render(testing::FurnaceMesh(), {"shell"},
                          fmt::format(fmt::runtime(testing::kFurnace), "path") + R"(
[medium]
sigma_a = 0.8
sigma_s = 1.2
g = 0.3
emission = 1
)",
                          2);
    ASSERT_TRUE(t);
    EXPECT_NEAR(MeanY(*t->film), 1.0, 0.03);
    // Without its emission the same medium darkens the furnace: the test can tell.
    const auto dark = Render(testing::FurnaceMesh(), {"shell"},
                             fmt::format(fmt::runtime(testing::kFurnace), "path") + R"(
[medium]
sigma_a = 0.8
sigma_s = 1.2
g = 0.3
)",
                             2);
    ASSERT_TRUE(dark);
    EXPECT_LT(MeanY(*dark->film), 0.8);
}

TEST(MediumEmissionConfigTest, EmissionKeysAreCheckedAndNamed) {
    auto error = [](const std::string& medium) {
        return testing::ConfigError(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[medium]\nsigma_a = 0.1\n" +
                medium + "\n",
            "dir/fire.toml");
    };
    EXPECT_EQ(error("emission = 2"), "");
    EXPECT_EQ(error("grid = \"fire.vdb\"\ntemperature_grid = \"temperature\"\n"
                    "temperature_scale = 1000\nemission_scale = 0.5"),
              "");
    EXPECT_EQ(error("grid = \"fire.vdb\"\nemission = 3\nemission_grid = \"flame\""), "");
    EXPECT_NE(error("temperature_grid = \"temperature\"").find("give that file as 'grid'"),
              std::string::npos);
    EXPECT_NE(error("grid = \"store\"\ntemperature_grid = \"t\"").find("the density grid only"),
              std::string::npos);
    EXPECT_NE(error("grid = \"fire.vdb\"\ntemperature_grid = \"t\"\nemission = 1").find("not both"),
              std::string::npos);
    EXPECT_NE(error("grid = \"fire.vdb\"\nemission_grid = \"flame\"").find("scales a radiance"),
              std::string::npos);
    EXPECT_NE(error("emission = 1\ntemperature_scale = 2").find("needs a temperature_grid"),
              std::string::npos);
    EXPECT_NE(error("emission_scale = 2").find("needs an emission"), std::string::npos);
    EXPECT_NE(error("emission = 1\nemission_scale = -1").find("emission_scale"), std::string::npos);
    // A solid's medium may glow, from a radiance; grids it has none.
    StatusOr<SceneConfig> solid = ParseSceneConfig(
        "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[materials.lava]\ntype = "
        "\"dielectric\"\n[materials.lava.medium]\nsigma_a = 5\nemission = 1\n",
        "dir/lava.toml");
    EXPECT_TRUE(solid.ok()) << solid.status().message();
    StatusOr<SceneConfig> solid_grid = ParseSceneConfig(
        "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[materials.lava]\ntype = "
        "\"dielectric\"\n[materials.lava.medium]\nsigma_a = 5\ntemperature_grid = \"t\"\n",
        "dir/lava.toml");
    ASSERT_FALSE(solid_grid.ok());
    EXPECT_NE(
        std::string(solid_grid.status().message()).find("materials.lava.medium.temperature_grid"),
        std::string::npos)
        << solid_grid.status().message();
}

// Photon mode emits no photons from media: an emitting medium there is refused, naming the table,
// rather than rendered without the light it casts. A negative emission is refused too.
TEST_F(MediumEmissionTest, PhotonModeAndNegativeEmissionAreRefused) {
    auto build_error = [](const std::string& medium, const std::string& mode) {
        return testing::LampSceneError(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[materials.lamp]\n[medium]\n"
            "sigma_a = 0.5\n" +
                medium + "\n[render]\nmode = \"" + mode + "\"\n",
            "glow.toml");
    };
    EXPECT_EQ(build_error("emission = 1", "path"), "");
    const std::string photon = build_error("emission = 1", "photon");
    EXPECT_NE(photon.find("glow.toml"), std::string::npos) << photon;
    EXPECT_NE(photon.find("render.mode = \"path\""), std::string::npos) << photon;
    EXPECT_NE(build_error("emission = -1", "path").find("medium.emission is -1"),
              std::string::npos);
}

}  // namespace
}  // namespace nave::render
