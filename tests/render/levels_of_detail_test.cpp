// Levels of detail (docs/render.md, "Levels of detail"): which level a footprint chooses, the
// clearance a ray keeps from the other levels' copies of the surface it left, and renders with
// levels: paged equals in-core, render.lod = "full" equals a model without levels, and a
// thin-walled room neither leaks the sun in nor darkens against full detail.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "render_test_util.h"
#include "src/core/progress.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/scene/lights/point_light.h"
#include "src/render/scene/lights/sun_light.h"
#include "src/render/stream/level_choice.h"
#include "src/render/stream/pager.h"
#include "src/render/stream/stream_scheduler.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {
namespace {

using testing::BuildAndRender;
using testing::GridSource;
using testing::GridSourceWithLevels;
using testing::MaxRelativeDifference;
using testing::MeanY;
using testing::NamedMaterials;

constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(LevelChoice, TheCoarsestLevelWhoseErrorTheFootprintHides) {
    const float errors[] = {0.f, 0.01f, 0.1f, kInf};
    EXPECT_EQ(ChooseLevel(errors, 4, 0.f), 0u);  // a camera ray at the camera
    EXPECT_EQ(ChooseLevel(errors, 4, 0.019f), 0u);
    EXPECT_EQ(ChooseLevel(errors, 4, 0.02f), 1u);  // error = half the footprint
    EXPECT_EQ(ChooseLevel(errors, 4, 0.5f), 2u);
    EXPECT_EQ(ChooseLevel(errors, 4, 1e30f), 2u);  // a level the brick lacks is never chosen
    EXPECT_EQ(ChooseLevel(errors, 1, 1e30f), 0u);  // without levels
}

TEST(LevelChoice, RaysKeepTheirOriginsLevelUntilPastEveryCopyOfTheirSurface) {
    // Off a level with a 1 cm error, with a footprint of 6 cm (levels of up to 3 cm near the
    // origin): copies up to 4 cm apart, kept for four times that.
    EXPECT_NEAR(LevelReach(0.01f, 0.06f, 1.f), 0.16f, 1e-6f);
    // The levels near the origin are never coarser than the model's coarsest.
    EXPECT_NEAR(LevelReach(0.01f, 10.f, 0.05f), 0.24f, 1e-6f);
    // Without levels, nothing to keep: full detail renders as without them.
    EXPECT_EQ(LevelReach(0, 0.5f, 0), 0.f);
}

// A shadow ray is as wide as its light: the sun's penumbrae blur over its disc, 0.53 degrees (the
// disc of radius 0.2666 degrees, as at 1 AU), so its shadows' occluders may be read at the levels
// that footprint allows; a point light's shadows are sharp and keep full detail.
TEST(LevelChoice, ShadowRaysAreAsWideAsTheirLight) {
    const double radius = 0.2666 * M_PI / 180;
    const SunLight sun(Vec3f(0, 0, 1), radius, Spectrum::Constant(1.f));
    EXPECT_NEAR(sun.ShadowSpread(), 9.306e-3f, 1e-6f);
    const PointLight lamp(Vec3f(0, 0, 2), Spectrum::Constant(1.f));
    EXPECT_EQ(lamp.ShadowSpread(), 0.f);
    // From a camera hit 20 m away at a pixel's 2.65 mrad (5.3 cm wide), a sun shadow ray reaches
    // a level of 5 cm error 5 m along, where the camera's own cone would have needed 17.7 m.
    const float errors[] = {0.f, 0.05f};
    RayRecord r{};
    r.cone_width = 20 * 2.65e-3f;
    r.cone_spread = 2.65e-3f;
    EXPECT_EQ(ChooseLevel(errors, 2, ConeWidthAt(r, 6.f)), 0u);
    r.cone_spread = std::max(r.cone_spread, sun.ShadowSpread());
    EXPECT_EQ(ChooseLevel(errors, 2, ConeWidthAt(r, 4.f)), 0u);
    EXPECT_EQ(ChooseLevel(errors, 2, ConeWidthAt(r, 6.f)), 1u);
}

// A pixel's value is the mean of what covers it, and a coarse level does not cover what the full
// mesh does (thin parts thin out): a camera ray, and a path that has since only crossed glass or
// met mirrors, keep full detail however wide their footprint grows; a diffuse or glossy bounce
// (LeaveSurface, scattered) lets the path use levels, and shadow rays and photons use them as wide
// as they are.
TEST(LevelChoice, PathsUseLevelsOnlyPastADiffuseOrGlossyBounce) {
    RayRecord camera{};
    camera.kind = kPathRay;
    camera.cone_spread = 2.65e-3f;  // a pixel's
    EXPECT_FALSE(UsesLevels(camera));
    SurfaceHit mirror{};
    mirror.ng = mirror.ns = Vec3f(0, 0, 1);
    RayRecord reflected = camera;
    LeaveSurface(reflected, mirror, Vec3f(0, 0, 1), 40.f, /*scattered=*/false);
    EXPECT_FALSE(UsesLevels(reflected)) << "wide, but still the pixel's cone";
    EXPECT_NEAR(reflected.cone_width, 0.106f, 1e-6f);
    RayRecord bounced = camera;
    LeaveSurface(bounced, mirror, Vec3f(0, 0, 1), 40.f, /*scattered=*/true);
    EXPECT_TRUE(UsesLevels(bounced));
    RayRecord shadow = camera;
    shadow.kind = kShadowRay;
    EXPECT_TRUE(UsesLevels(shadow));
    RayRecord photon = camera;
    photon.kind = kPhotonRay;
    EXPECT_TRUE(UsesLevels(photon));
}

/// Levels of a few cm and a decimetre on these metre-sized test bricks.
store::LevelOptions TestLevels() {
    store::LevelOptions o;
    o.relative_errors = {0.01, 0.04};
    return o;
}

/// The room's levels: errors of about 1 and 4 cm (twice 0.3 % and 1 % of a brick's extent, 3.5 m),
/// as the abbey's levels are to its spaces.
store::LevelOptions RoomLevels() {
    store::LevelOptions o;
    o.relative_errors = {0.003, 0.01};
    return o;
}

class LevelsOfDetail : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

// Balls on a floor (curved: their levels have an error), cut into 2 x 2 x 1 bricks.
store::BrickMesh Balls() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {3, 0, 0}, {0, 3, 0}, 24, 0);
    for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j)
            AppendSphere(&m, {-1.5f + 3.f * float(i), -1.5f + 3.f * float(j), 0.8f}, 0.7f, 32, 64,
                         1);
    }
    return m;
}

SceneConfig BallsConfig(const std::string& mode, const std::string& lod) {
    const std::string text =
        "[camera]\nposition = [6, 5, 4]\nlook_at = [0, 0, 0.5]\nfov_deg = 50\n"
        "resolution = [128, 96]\n" +
        testing::SunSkyFloorAndBall() +
        fmt::format(
            "[render]\nmode = \"{}\"\nspp = 2\niterations = 2\n"
            "photons_per_iteration = 20000\nseed = 3\nlod = \"{}\"\n",
            mode, lod);
    auto config = ParseSceneConfig(text, "balls.toml");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    return config.ok() ? *config : SceneConfig();
}

/// Whether any brick's coarser level is resident in `source` (in-core, a level loaded is a level
/// some ray was traced against).
bool SomeCoarseLevelResident(const BrickSource& source) {
    for (uint32_t slot = source.brick_count(); slot < source.slot_count(); ++slot) {
        if (source.IsResident(slot)) return true;
    }
    return false;
}

// With `all_kept`, a budget that keeps every coarse level resident; else one that holds only some
// of them (KeptLevels: the smallest, within half the budget).
void ExpectPagedEqualsInCore(const std::string& mode, double bound, bool all_kept = true) {
    const std::vector<std::string> names = {"floor", "ball"};
    auto in_core = BuildAndRender(
        GridSourceWithLevels(Balls(), NamedMaterials(names), {4, 4, 1}, TestLevels()),
        BallsConfig(mode, "auto"));
    ASSERT_TRUE(in_core != nullptr);
    ASSERT_TRUE(in_core->status.ok()) << in_core->status.ToString();
    ASSERT_GT(in_core->source->level_count(), 1u);
    EXPECT_TRUE(SomeCoarseLevelResident(*in_core->source));

    const BrickBudgetMinimum m = MinimumBrickBudget(*in_core->source, true);
    EXPECT_GT(m.kept_bytes, 0u);
    PagerOptions paging;
    if (all_kept) {
        // The kept levels and the two largest others: many reloads.
        paging.brick_budget_bytes = std::max(m.kept_bytes * 2, m.kept_bytes + m.min_bytes);
        EXPECT_TRUE(KeepsCoarseLevels(m, paging.brick_budget_bytes));
    } else {
        // Half the coarse levels' bytes beside the two largest others.
        paging.brick_budget_bytes = m.min_bytes + m.kept_bytes / 2;
        ASSERT_FALSE(KeepsCoarseLevels(m, paging.brick_budget_bytes));
        const std::vector<bool> kept = KeptLevels(*in_core->source, m, paging.brick_budget_bytes);
        uint64_t kept_bytes = 0;
        size_t kept_count = 0, coarse_count = 0;
        for (uint32_t b = 0; b < kept.size(); ++b) {
            if (KeptResident(*in_core->source, b)) ++coarse_count;
            if (!kept[b]) continue;
            EXPECT_TRUE(KeptResident(*in_core->source, b)) << "slot " << b;
            kept_bytes += in_core->source->EstimatedResidentBytes(b);
            ++kept_count;
        }
        EXPECT_GT(kept_count, 0u);
        EXPECT_LT(kept_count, coarse_count);
        EXPECT_LE(kept_bytes, paging.brick_budget_bytes / 2);
        EXPECT_LE(kept_bytes + m.min_bytes, paging.brick_budget_bytes);
    }
    paging.spill_dir = std::filesystem::temp_directory_path();
    testing::RunOptions run;
    run.paging = &paging;
    auto paged = BuildAndRender(
        GridSourceWithLevels(Balls(), NamedMaterials(names), {4, 4, 1}, TestLevels()),
        BallsConfig(mode, "auto"), run);
    ASSERT_TRUE(paged != nullptr);
    ASSERT_TRUE(paged->status.ok()) << paged->status.ToString();
    EXPECT_GT(paged->stats.residency.evictions, 0u);
    EXPECT_LE(paged->stats.residency.peak_resident_bytes, paging.brick_budget_bytes);
    EXPECT_GT(MeanY(*paged->film), 0.0);
    EXPECT_LT(MaxRelativeDifference(*in_core->film, *paged->film), bound) << mode;
}

// The level is chosen by the ray's footprint, never by what is resident.
TEST_F(LevelsOfDetail, PagedRenderEqualsInCorePath) { ExpectPagedEqualsInCore("path", 1e-9); }
TEST_F(LevelsOfDetail, PagedRenderEqualsInCorePhoton) { ExpectPagedEqualsInCore("photon", 1e-9); }
TEST_F(LevelsOfDetail, PagedRenderWithSomeCoarseLevelsKeptEqualsInCore) {
    ExpectPagedEqualsInCore("path", 1e-9, /*all_kept=*/false);
}

TEST_F(LevelsOfDetail, FullDetailIgnoresTheLevels) {
    const std::vector<std::string> names = {"floor", "ball"};
    auto without = BuildAndRender(GridSource(Balls(), NamedMaterials(names), {4, 4, 1}),
                                  BallsConfig("path", "auto"));
    auto full = BuildAndRender(
        GridSourceWithLevels(Balls(), NamedMaterials(names), {4, 4, 1}, TestLevels()),
        BallsConfig("path", "full"));
    ASSERT_TRUE(without != nullptr && full != nullptr);
    ASSERT_TRUE(without->status.ok() && full->status.ok());
    EXPECT_EQ(full->source->level_count(), 1u);
    EXPECT_EQ(without->source->level_count(), 1u);
    // The same rays through the same triangles; only the order of the film's sums may differ.
    EXPECT_LT(MaxRelativeDifference(*without->film, *full->film), 1e-9);
}

// The pass over the model before a render (the sky's portals) reads each brick's coarsest level
// when levels are in use: fewer triangles, and no full-detail brick loaded for it alone.
TEST_F(LevelsOfDetail, TheModelScanReadsEachBricksCoarsestLevel) {
    auto source =
        GridSourceWithLevels(Balls(), NamedMaterials({"floor", "ball"}), {4, 4, 1}, TestLevels());
    ASSERT_TRUE(source != nullptr);
    ASSERT_TRUE(source->UseLevels(8).ok());
    ASSERT_GT(source->level_count(), 1u);
    auto scheduler = StreamScheduler::Create(*source, PagerOptions(), {}, 1000);
    ASSERT_TRUE(scheduler.ok()) << scheduler.status().ToString();
    uint64_t triangles[2] = {0, 0};
    uint32_t coarse_bricks = 0;
    for (const ScanDetail detail : {ScanDetail::kCoarsest, ScanDetail::kFull}) {
        const bool full = detail == ScanDetail::kFull;
        const Status pass =
            (*scheduler)->ForEachBrick("scan", detail, [&](uint32_t b, const ResidentBrick& brick) {
                const uint32_t expected = full ? 0 : source->LevelsOf(b) - 1;
                EXPECT_EQ(brick.lod().level, expected) << "brick " << b;
                if (!full && expected > 0) ++coarse_bricks;
                triangles[full] += brick.mesh().TriangleCount();
                return Status::Ok();
            });
        ASSERT_TRUE(pass.ok()) << pass.ToString();
        if (full) continue;
        for (uint32_t b = 0; b < source->brick_count(); ++b) {
            if (source->LevelsOf(b) > 1) {
                EXPECT_FALSE(source->IsResident(source->SlotOf(b, 0))) << "brick " << b;
            }
        }
    }
    EXPECT_GT(coarse_bricks, 0u);
    EXPECT_LT(triangles[0], triangles[1]);
}

// A room whose walls are two shells 50 cm apart (an inward sphere of 2 m inside an outward one),
// under a strong sun, with a lamp panel and a ball inside. Coarse levels of the inner shell lie
// within their error of it, which is far below the wall's thickness.
store::BrickMesh ThinWalledRoom() {
    store::BrickMesh m;
    AppendSphere(&m, {0, 0, 0}, 2.0f, 48, 96, 0, /*inward=*/true);
    AppendSphere(&m, {0, 0, 0}, 2.5f, 48, 96, 0);
    AppendSphere(&m, {0.7f, 0.4f, -0.9f}, 0.5f, 24, 48, 1);
    // A flat lamp facing down (a curved one would shrink at coarse levels, and with it the light
    // that paths find by hitting it: a bias of its own, measured on the abbey in docs/render.md).
    AppendQuad(&m, {-0.3f, 0.3f, 1.4f}, {0.25f, 0, 0}, {0, -0.25f, 0}, 1, 2);
    return m;
}

SceneConfig RoomConfig(const std::string& lod, float lamp, int spp, int seed) {
    const std::string text = fmt::format(R"(
[camera]
position = [-1.2, -1.0, -0.3]
look_at = [0.5, 0.5, 0]
fov_deg = 70
resolution = [40, 30]
[sun]
direction = [0.3, -0.2, 0.9]
[materials.wall]
reflectance = 0.7
[materials.ball]
reflectance = 0.5
[materials.lamp]
reflectance = 0.5
emission = {}
[render]
mode = "path"
spp = {}
max_depth = 6
seed = {}
lod = "{}"
)",
                                         lamp, spp, seed, lod);
    auto config = ParseSceneConfig(text, "room.toml");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    return config.ok() ? *config : SceneConfig();
}

std::unique_ptr<testing::TestRender> RenderRoom(const std::string& lod, float lamp, int spp,
                                                int seed) {
    return BuildAndRender(
        GridSourceWithLevels(ThinWalledRoom(), NamedMaterials({"wall", "ball", "lamp"}), {2, 2, 2},
                             RoomLevels()),
        RoomConfig(lod, lamp, spp, seed));
}

TEST_F(LevelsOfDetail, AThinWalledRoomLetsNoSunlightIn) {
    // 240 000 paths: rays started on a coarse facet (no LevelOffset) let some in at this count,
    // and so did reflections that a bent shading normal sent through the wall at full detail
    // (Bsdf::SetGeometricNormal).
    auto full = RenderRoom("full", 0, 200, 9);
    auto lod = RenderRoom("auto", 0, 200, 9);
    ASSERT_TRUE(full != nullptr && lod != nullptr);
    ASSERT_TRUE(full->status.ok() && lod->status.ok());
    EXPECT_TRUE(SomeCoarseLevelResident(*lod->source));
    // Closed: not one sample of the sun or the sky inside, at full detail nor with levels.
    EXPECT_EQ(MeanY(*full->film), 0.0);
    EXPECT_EQ(MeanY(*lod->film), 0.0);
}

TEST_F(LevelsOfDetail, AThinWalledRoomLitFromInsideAgreesWithFullDetail) {
    // Rays meeting a coarse copy of the surface they left from behind would darken the room;
    // rays slipping through the walls would lose light; rays started too far off the walls would
    // brighten it. The lamp is small and found by paths alone, so one render's mean varies by a
    // few percent from seed to seed: four seeds' sums, per quarter of the image and in all.
    double full_sum[2][2] = {}, lod_sum[2][2] = {};
    for (int seed = 1; seed <= 4; ++seed) {
        auto full = RenderRoom("full", 20, 100, seed);
        auto lod = RenderRoom("auto", 20, 100, seed);
        ASSERT_TRUE(full != nullptr && lod != nullptr);
        ASSERT_TRUE(full->status.ok() && lod->status.ok());
        for (int qy = 0; qy < 2; ++qy) {
            for (int qx = 0; qx < 2; ++qx) {
                for (int y = qy * 15; y < qy * 15 + 15; ++y) {
                    for (int x = qx * 20; x < qx * 20 + 20; ++x) {
                        full_sum[qy][qx] += full->film->PixelXYZ(uint32_t(y * 40 + x)).y;
                        lod_sum[qy][qx] += lod->film->PixelXYZ(uint32_t(y * 40 + x)).y;
                    }
                }
            }
        }
    }
    double full_total = 0, lod_total = 0;
    for (int qy = 0; qy < 2; ++qy) {
        for (int qx = 0; qx < 2; ++qx) {
            ASSERT_GT(full_sum[qy][qx], 0.0);
            EXPECT_NEAR(lod_sum[qy][qx] / full_sum[qy][qx], 1.0, 0.05)
                << "quarter " << qx << ", " << qy;
            full_total += full_sum[qy][qx];
            lod_total += lod_sum[qy][qx];
        }
    }
    EXPECT_NEAR(lod_total / full_total, 1.0, 0.025);
}

// A glass dome (a thin pane, an inward sphere of 2 m) with lead cames 3 mm outside it: a shell
// of latitude bands covering three quarters of it, as the abbey's windows hold theirs a few
// millimetres behind the glass. Inside, a ball lit by a uniform sky through both.
store::BrickMesh GlazedDome() {
    store::BrickMesh m;
    AppendSphere(&m, {0, 0, 0}, 2.0f, 48, 96, 0, /*inward=*/true);
    store::BrickMesh shell;
    constexpr int kRings = 48;
    AppendSphere(&shell, {0, 0, 0}, 2.003f, kRings, 96, 1);
    std::vector<uint32_t> vertex_of(shell.VertexCount(), UINT32_MAX);
    for (size_t t = 0; t < shell.TriangleCount(); ++t) {
        const auto p = shell.TrianglePositions(t);
        const Vec3f c = (p[0] + p[1] + p[2]) / 3.f;
        const int ring = int(std::acos(std::clamp(c.z / Length(c), -1.f, 1.f)) / M_PI * kRings);
        if (ring % 4 == 0) continue;  // an open band in four
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = shell.indices[3 * t + k];
            if (vertex_of[v] == UINT32_MAX) {
                vertex_of[v] = uint32_t(m.positions.size());
                m.positions.push_back(shell.positions[v]);
                m.normals.push_back(shell.normals[v]);
            }
            m.indices.push_back(vertex_of[v]);
        }
        m.material_ids.push_back(1);
    }
    AppendSphere(&m, {0.5f, 0.3f, -0.8f}, 0.5f, 24, 48, 2);
    return m;
}

std::unique_ptr<testing::TestRender> RenderDome(const std::string& lod, int seed) {
    const std::string text = fmt::format(R"(
[camera]
position = [-1.0, -0.8, -0.3]
look_at = [0.5, 0.3, -0.8]
fov_deg = 60
resolution = [32, 24]
[sky]
radiance = 1.0
[materials.pane]
type = "thin_dielectric"
eta = 1.5
[materials.came]
reflectance = 0.05
[materials.ball]
reflectance = 0.7
[render]
mode = "path"
spp = 32
max_depth = 4
seed = {}
lod = "{}"
)",
                                         seed, lod);
    auto config = ParseSceneConfig(text, "dome.toml");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    if (!config.ok()) return nullptr;
    return BuildAndRender(
        GridSourceWithLevels(GlazedDome(), NamedMaterials({"pane", "came", "ball"}), {4, 4, 4},
                             TestLevels()),
        *config);
}

TEST_F(LevelsOfDetail, PathsThroughAPaneMeetWhatLiesJustBehindIt) {
    // A path crossing a coarse pane goes on from the pane itself: started off it by half the
    // level's error (LevelOffset, 8 mm and more here), it passed over the cames and the ball came
    // out 23 % brighter than at full detail (0.5 % with the paths going on from the pane).
    double full_sum = 0, lod_sum = 0;
    for (int seed = 1; seed <= 2; ++seed) {
        auto full = RenderDome("full", seed);
        auto lod = RenderDome("auto", seed);
        ASSERT_TRUE(full != nullptr && lod != nullptr);
        ASSERT_TRUE(full->status.ok() && lod->status.ok());
        EXPECT_TRUE(SomeCoarseLevelResident(*lod->source));
        full_sum += MeanY(*full->film);
        lod_sum += MeanY(*lod->film);
    }
    ASSERT_GT(full_sum, 0.0);
    EXPECT_NEAR(lod_sum / full_sum, 1.0, 0.05);
}

}  // namespace
}  // namespace nave::render
