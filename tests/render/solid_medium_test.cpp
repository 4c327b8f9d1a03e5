// Media inside closed solids ([materials.NAME.medium]): a ray carries the medium it is in
// (RayRecord::medium) and changes it only where it crosses a solid's surface (MediumPast). Beer-
// Lambert through a tinted block, the air's medium kept out of a solid, a white furnace with a
// scattering ball of water in it (path and photon mode), one brick against many, and the config's
// errors.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render_test_util.h"
#include "src/core/progress.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {
namespace {

using testing::MeanY;
using testing::Render;

class SolidMediumTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

// A solid's surface moves a ray in and out of its inside, and only where it refracts: a reflection
// there, or any surface with no inside, leaves the ray in the medium it was in.
TEST(MediumPastTest, OnlyACrossingOfASolidsSurfaceChangesTheMedium) {
    SurfaceMaterial water, stone;
    water.material = DielectricMaterial{};
    water.medium_inside = 3;
    SurfaceHit h;
    h.ng = Vec3f(0, 0, 1);  // facing out, up
    h.material = &water;
    RayRecord r;
    r.dir = Vec3f(0, 0, -1);  // arriving from above, outside
    r.medium = kOutsideMedium;
    EXPECT_EQ(MediumPast(r, h, Vec3f(0.6f, 0, -0.8f)), 3) << "refracted in";
    EXPECT_EQ(MediumPast(r, h, Vec3f(0.6f, 0, 0.8f)), kOutsideMedium) << "reflected off";
    r.dir = Vec3f(0, 0, 1);  // arriving from below, inside
    r.medium = 3;
    EXPECT_EQ(MediumPast(r, h, Vec3f(0, 0.6f, 0.8f)), kOutsideMedium) << "refracted out";
    EXPECT_EQ(MediumPast(r, h, Vec3f(0, 0.6f, -0.8f)), 3) << "totally reflected inside";
    h.material = &stone;  // no inside: a ray keeps its medium through anything
    EXPECT_EQ(MediumPast(r, h, Vec3f(0, 0.6f, 0.8f)), 3);
}

/// The lamp (testing::LampMesh) behind a block x in [1, 2] (material 1, "block"), 1 m along the
/// view.
store::BrickMesh LampBehindABlock() {
    store::BrickMesh mesh = testing::LampMesh();
    AppendBox(&mesh, Bounds3f{{1, -1, -1}, {2, 1, 1}}, 1);
    return mesh;
}

// The lamp seen through 1 m of a solid of index 1 (no Fresnel reflection, no bending) filled with
// an absorber: dimmed by e^(-σa), the same as [medium]'s slab (MediumRenderTest). In hazy air that
// absorbs too, over x in [0.5, 2.5], the air's medium stops at the solid's surface: e^(-0.5 - 0.2)
// with a medium inside, e^(-0.5) through a clear solid, where an air that reached in would give
// e^(-1.2) and e^(-1).
TEST_F(SolidMediumTest, BeerLambertInsideASolidAndTheAirKeptOut) {
    const std::string lamp = testing::kLampConfig;
    const auto clear = Render(testing::LampMesh(), {"lamp"}, lamp, 2);
    ASSERT_TRUE(clear);
    const double lit = MeanY(*clear->film);
    ASSERT_GT(lit, 0.0);
    const std::string block = "[materials.block]\ntype = \"dielectric\"\neta = 1.0\n";
    const std::string tinted = block + "[materials.block.medium]\nsigma_a = 0.7\n";
    const std::string air = "[medium]\nbox_min = [0.5, -1, -1]\nbox_max = [2.5, 1, 1]\n";
    struct Case {
        std::string config;
        double expected;
    };
    const Case cases[] = {
        {block, 1.0},
        {tinted, std::exp(-0.7)},
        {block + air + "sigma_a = 0.5\n", std::exp(-0.5)},
        {block + "[materials.block.medium]\nsigma_a = 0.2\n" + air + "sigma_a = 0.5\n",
         std::exp(-0.7)},
    };
    for (const Case& c : cases) {
        const auto t = Render(LampBehindABlock(), {"lamp", "block"}, lamp + c.config, 2);
        ASSERT_TRUE(t) << c.config;
        // The view's rays lie within 0.5° of the block's normal: up to 4e-5 longer inside it.
        EXPECT_NEAR(MeanY(*t->film) / lit, c.expected, 1e-4) << c.config;
    }
}

/// The furnace (testing::FurnaceMesh, material 0 "shell") with a ball of water (material 1,
/// "water") in front of the camera, across the planes that cut it into 2 x 2 x 2 bricks.
store::BrickMesh FurnaceWithABall() {
    store::BrickMesh mesh = testing::FurnaceMesh();
    AppendSphere(&mesh, {0.55f, 0.1f, 0.03f}, 0.3f, 16, 32, 1);
    return mesh;
}

std::string FurnaceWithWater(const std::string& mode) {
    return fmt::format(fmt::runtime(testing::kFurnace), mode) + R"(
[materials.water]
type = "dielectric"
eta = 1.33
[materials.water.medium]
sigma_s = 3.0
g = 0.4
)";
}

// In the white furnace (L = 1 everywhere), a ball of glass-clear water that scatters and absorbs
// nothing changes nothing: what enters it leaves it, refracted in and out (the radiance's η²
// inside, Veach 1997 §5.2, cancels on the way out) and scattered inside. Paths cross the ball's
// surface into its medium and out, brick to brick; photons too.
TEST_F(SolidMediumTest, AWhiteFurnaceWithAScatteringBallOfWaterStaysAtOne) {
    for (const auto& [mode, tolerance] : {std::pair{"path", 0.03}, {"photon", 0.03}}) {
        const auto t = Render(FurnaceWithABall(), {"shell", "water"}, FurnaceWithWater(mode), 2);
        ASSERT_TRUE(t);
        EXPECT_NEAR(MeanY(*t->film), 1.0, tolerance) << mode;
    }
}

// An absorbing ball darkens the furnace where it is seen, and the image does not depend on how the
// model is cut: a path's flight inside the ball is summed brick by brick.
TEST_F(SolidMediumTest, OneBrickAndManyGiveTheSameImage) {
    const std::string config = FurnaceWithWater("path") + "sigma_a = 0.8\n";
    const auto one = Render(FurnaceWithABall(), {"shell", "water"}, config, 1, 1);
    const auto many = Render(FurnaceWithABall(), {"shell", "water"}, config, 3, 2);
    ASSERT_TRUE(one && many);
    EXPECT_GT(many->stats.brick_moves, 0u);
    EXPECT_LT(MeanY(*one->film), 0.95) << "the ball absorbs";
    EXPECT_LT(testing::MaxRelativeDifference(*one->film, *many->film), 1e-5);
}

TEST(SolidMediumConfigTest, AMediumFillsOnlyASolidAndOnlyWhole) {
    auto error = [](const std::string& material) {
        return testing::ConfigError(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[materials.water]\n" + material,
            "pool.toml");
    };
    EXPECT_EQ(error("type = \"dielectric\"\n[materials.water.medium]\nsigma_s = 0.1\ng = 0.5"), "");
    EXPECT_NE(error("reflectance = 0.5\n[materials.water.medium]\nsigma_s = 0.1")
                  .find("materials.water.medium: only a solid dielectric (type = \"dielectric\") "
                        "has an inside to fill; a diffuse material has none"),
              std::string::npos);
    EXPECT_NE(error("type = \"thin_dielectric\"\n[materials.water.medium]\nsigma_s = 0.1")
                  .find("a thin_dielectric material has none"),
              std::string::npos);
    EXPECT_NE(error("type = \"dielectric\"\n[materials.water.medium]\nsigma_s = 0.1\n"
                    "box_min = [0, 0, 0]\nbox_max = [1, 1, 1]")
                  .find("materials.water.medium.box_min: a solid's medium fills its inside"),
              std::string::npos);
    EXPECT_NE(error("type = \"dielectric\"\n[materials.water.medium]\ngrid = \"dust.vdb\"")
                  .find("materials.water.medium.grid"),
              std::string::npos);
    EXPECT_NE(error("type = \"dielectric\"\n[materials.water.medium]\ng = 0.5")
                  .find("missing 'sigma_s' and 'sigma_a'"),
              std::string::npos);
    EXPECT_NE(error("type = \"dielectric\"\n[materials.water.medium]\nsigma_s = 0.1\nsmoke = 1")
                  .find("unknown key 'materials.water.medium.smoke'"),
              std::string::npos);
    // A ray counts its scatterings in a byte.
    StatusOr<SceneConfig> deep = ParseSceneConfig(
        "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[render]\nmax_depth = 256\n",
        "deep.toml");
    ASSERT_FALSE(deep.ok());
    EXPECT_NE(deep.status().message().find("render.max_depth: 256 is out of range [1, 255]"),
              std::string::npos)
        << deep.status().message();
}

// What only the scene can tell: a builtin that is no solid, and a negative coefficient, named with
// the material's table.
TEST_F(SolidMediumTest, ABuiltinWithNoInsideAndANegativeCoefficientAreNamed) {
    auto build_error = [](const std::string& material) {
        return testing::LampSceneError(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[materials.default]\n" + material,
            "pool.toml");
    };
    EXPECT_EQ(build_error("builtin = \"bk7\"\n[materials.default.medium]\nsigma_a = 0.1"), "");
    EXPECT_NE(build_error("builtin = \"gold\"\n[materials.default.medium]\nsigma_a = 0.1")
                  .find("materials.default.medium: only a solid dielectric has an inside to "
                        "fill; materials.default is not one"),
              std::string::npos);
    EXPECT_NE(build_error("type = \"dielectric\"\n[materials.default.medium]\nsigma_a = -0.1")
                  .find("materials.default.medium.sigma_a is -0.1"),
              std::string::npos);
}

}  // namespace
}  // namespace nave::render
