// Photon mode's caustic points (src/render/transport/visible_points.h): with final gathering a
// pixel's caustic point takes the photons whose every bounce was specular and no other, beside its
// visible point, which takes every photon; both add to the pixel. And the specular chain that
// decides which photons those are (src/render/stream/ray.h).

#include "src/render/transport/visible_points.h"

#include <gtest/gtest.h>

#include <numbers>
#include <vector>

#include "src/render/scene/scene.h"
#include "src/render/stream/ray.h"
#include "store/brick_tree.h"

namespace nave::render {
namespace {

TEST(SpecularChain, HoldsWhileEveryBounceIsSpecular) {
    uint8_t flags = kFromSky;
    EXPECT_FALSE(flags & kSpecularChain);  // no bounce yet
    flags = ExtendSpecularChain(flags, true);
    EXPECT_TRUE(flags & kSpecularChain);
    flags = ExtendSpecularChain(flags, true);
    EXPECT_TRUE(flags & kSpecularChain);
    flags = ExtendSpecularChain(flags, false);
    EXPECT_FALSE(flags & kSpecularChain);
    flags = ExtendSpecularChain(flags, true);  // specular after a diffuse bounce: no caustic
    EXPECT_FALSE(flags & kSpecularChain);
    EXPECT_TRUE(flags & kFromSky);  // the other flags are kept
    EXPECT_FALSE(ExtendSpecularChain(0, false) & kSpecularChain);
}

/// One pixel whose visible point and caustic point lie at the origin of a floor facing up, in a
/// model of one brick.
struct OnePixel {
    OnePixel() : points(1, 1, /*initial_radius=*/0.5f, /*alpha=*/2.f / 3, /*caustic_points=*/true) {
        floor.name = "floor";
        floor.material = DiffuseMaterial{Spectrum::Constant(0.5f)};
        store::BrickTreeNode leaf;
        leaf.brick = 0;
        tree = store::BrickTree(Bounds3f({-1, -1, -1}, {1, 1, 1}), {leaf});
        points.BeginIteration(/*seed=*/1, /*iteration=*/0, /*photons=*/1);
    }
    float Deposit(bool caustic) {
        const SampledWavelengths lambda = SampledWavelengths::SampleVisible(0.5f);
        return points.Deposit(0, Vec3f(0.1f, 0, 0), Vec3f(0, 0, 1), Normalize(Vec3f(0, 1, 1)),
                              SampledSpectrum(1.f), lambda, VisiblePoints::kOwnWavelengths,
                              caustic);
    }
    void AddVisible() {
        points.Add(0, Vec3f(0, 0, 0), Vec3f(0, 0, 1), Vec3f(0, 0, 1), floor, nullptr, {},
                   SampledSpectrum(1.f), SampledWavelengths::SampleVisible(0.3f));
    }
    void AddCaustic() {
        points.AddCaustic(0, Vec3f(0, 0, 0), Vec3f(0, 0, 1), Vec3f(0, 0, 1), floor, nullptr, {},
                          SampledSpectrum(1.f), SampledWavelengths::SampleVisible(0.3f));
    }
    SurfaceMaterial floor;
    store::BrickTree tree;
    VisiblePoints points;
};

TEST(CausticPoints, TakeCausticPhotonsOnly) {
    OnePixel px;
    ASSERT_TRUE(px.points.caustic_points());
    px.AddCaustic();
    px.points.BuildBrickGrids(px.tree);
    EXPECT_EQ(px.Deposit(/*caustic=*/false), 0.f);
    EXPECT_GT(px.Deposit(/*caustic=*/true), 0.f);
}

TEST(CausticPoints, AddToTheirPixelBesideItsVisiblePoint) {
    OnePixel px;
    px.AddVisible();
    px.AddCaustic();
    px.points.BuildBrickGrids(px.tree);
    const float ordinary = px.Deposit(/*caustic=*/false);
    const float caustic = px.Deposit(/*caustic=*/true);
    ASSERT_GT(ordinary, 0.f);
    EXPECT_FLOAT_EQ(caustic, 2 * ordinary);  // the same point twice: visible and caustic
    px.points.EndIteration(0);
    EXPECT_NEAR(px.points.IndirectXYZ(0, 1).y, 3.0 * ordinary / (std::numbers::pi * 0.25),
                1e-4 * ordinary);
}

TEST(CausticPoints, OnlyWhereAMaterialMakesCaustics) {
    RenderSettings settings;
    settings.mode = RenderSettings::Mode::kPhoton;
    settings.final_gather = true;
    std::vector<SurfaceMaterial> materials(2);
    materials[0].material = DiffuseMaterial{};
    materials[1].material = ThinGlassMaterial{};
    EXPECT_FALSE(UsesCausticPoints(settings, materials));  // panes do not bend light
    ConductorMaterial rough;
    rough.alpha_x = rough.alpha_y = 0.3f;
    materials[1].material = rough;
    EXPECT_FALSE(UsesCausticPoints(settings, materials));  // glossy, not specular
    materials[1].material = DielectricMaterial{};
    EXPECT_TRUE(UsesCausticPoints(settings, materials));
    materials[1].black = true;
    EXPECT_FALSE(UsesCausticPoints(settings, materials));
    materials[1].black = false;
    settings.final_gather = false;  // the visible points see caustic photons themselves
    EXPECT_FALSE(UsesCausticPoints(settings, materials));
    settings.final_gather = true;
    settings.mode = RenderSettings::Mode::kPath;
    EXPECT_FALSE(UsesCausticPoints(settings, materials));
}

}  // namespace
}  // namespace nave::render
