// The occupancy grid of a brick (src/render/bricks/occupancy_grid.h): a segment it calls empty
// meets no triangle, whatever the ray (random, along an axis, grazing a voxel face), and it does
// call the segments through a hollow room's air empty; the scheduler's Route passes over such
// bricks.

#include "store/occupancy_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render_test_util.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/stream/stream_scheduler.h"

namespace nave::render {
namespace {

struct Mesh {
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices;
    void Add(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
        const uint32_t first = uint32_t(positions.size());
        positions.insert(positions.end(), {a, b, c});
        indices.insert(indices.end(), {first, first + 1, first + 2});
    }
    void AddQuad(const Vec3f& corner, const Vec3f& u, const Vec3f& v) {
        Add(corner, corner + u, corner + u + v);
        Add(corner, corner + u + v, corner + v);
    }
};

// Whether o + t d meets triangle (a, b, c) for t in [t0, t1] (Möller & Trumbore 1997, "Fast,
// minimum storage ray-triangle intersection"), in double, with a margin that counts near misses
// as hits: the grid must call such segments non-empty too.
bool Hits(const Vec3d& o, const Vec3d& d, double t0, double t1, const Vec3d& a, const Vec3d& b,
          const Vec3d& c) {
    const Vec3d e1 = b - a, e2 = c - a, p = Cross(d, e2);
    const double det = Dot(e1, p);
    if (std::abs(det) < 1e-14) return false;
    const double inv = 1 / det;
    const Vec3d s = o - a;
    const double u = Dot(s, p) * inv;
    const Vec3d q = Cross(s, e1);
    const double v = Dot(d, q) * inv;
    const double t = Dot(e2, q) * inv;
    constexpr double kMargin = 1e-6;
    return u >= -kMargin && v >= -kMargin && u + v <= 1 + kMargin && t >= t0 - kMargin &&
           t <= t1 + kMargin;
}

bool MeshHits(const Mesh& m, const Vec3f& o, const Vec3f& d, float t0, float t1) {
    for (size_t i = 0; i < m.indices.size(); i += 3) {
        if (Hits(Vec3d(o), Vec3d(d), t0, t1, Vec3d(m.positions[m.indices[i]]),
                 Vec3d(m.positions[m.indices[i + 1]]), Vec3d(m.positions[m.indices[i + 2]])))
            return true;
    }
    return false;
}

TEST(OccupancyGrid, ASegmentCalledEmptyMeetsNoTriangle) {
    // Small triangles scattered in a 10 m box, and a few large slanted ones across it.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> in_box(0.f, 10.f), small(-0.3f, 0.3f);
    Mesh m;
    for (int i = 0; i < 300; ++i) {
        const Vec3f c{in_box(rng), in_box(rng), in_box(rng)};
        m.Add(c, c + Vec3f{small(rng), small(rng), small(rng)},
              c + Vec3f{small(rng), small(rng), small(rng)});
    }
    m.Add({0, 0, 0}, {10, 0, 3}, {0, 10, 7});
    const store::OccupancyGrid grid = store::OccupancyGrid::Of(m.positions, m.indices);
    EXPECT_GT(grid.MarkedFraction(), 0.0);
    EXPECT_LT(grid.MarkedFraction(), 0.5);
    std::uniform_real_distribution<float> around(-5.f, 15.f), unit(-1.f, 1.f), length(0.f, 20.f);
    int empty = 0, hit = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f o{around(rng), around(rng), around(rng)};
        Vec3f d{unit(rng), unit(rng), unit(rng)};
        if (i % 4 == 0) d[i / 4 % 3] = 0;        // along a plane of the grid's axes
        if (i % 8 == 0) d[(i / 8 + 1) % 3] = 0;  // along an axis
        if (Length(d) == 0) continue;
        d = Normalize(d);
        const float t0 = length(rng), t1 = t0 + length(rng);
        const bool meets = MeshHits(m, o, d, t0, t1);
        hit += meets;
        if (grid.SegmentEmpty(o, d, t0, t1)) {
            ++empty;
            ASSERT_FALSE(meets) << "ray " << i;
        }
    }
    EXPECT_GT(hit, 100);
    EXPECT_GT(empty, 5000);

    // As a store holds it (Encode, Decode): the same answers, the same marks; damage is named.
    const std::string bytes = grid.Encode();
    EXPECT_LT(bytes.size(), store::OccupancyGrid::kMemoryBytes);
    StatusOr<store::OccupancyGrid> stored = store::OccupancyGrid::Decode(bytes, "brick 3");
    ASSERT_TRUE(stored.ok()) << stored.status().ToString();
    EXPECT_EQ(stored->MarkedFraction(), grid.MarkedFraction());
    for (int i = 0; i < 2000; ++i) {
        const Vec3f o{around(rng), around(rng), around(rng)};
        const Vec3f d = Normalize(Vec3f{unit(rng), unit(rng), unit(rng) + 1e-3f});
        ASSERT_EQ(stored->SegmentEmpty(o, d, 0, 30), grid.SegmentEmpty(o, d, 0, 30)) << i;
    }
    std::string cut = bytes.substr(0, bytes.size() - 3);
    EXPECT_NE(
        store::OccupancyGrid::Decode(cut, "brick 3").status().message().find("brick 3: its bits"),
        std::string::npos);
    std::string other = bytes;
    other[0] = char(32);
    EXPECT_NE(store::OccupancyGrid::Decode(other, "brick 3").status().message().find("32 voxels"),
              std::string::npos);
    EXPECT_EQ(store::OccupancyGrid::Of({}, {}).Encode(), "");
}

TEST(OccupancyGrid, RaysThroughARoomsAirAreEmptyAndRaysToItsWallsAreNot) {
    // A closed 20 x 10 x 8 m room of two triangles per wall, and a thin screen across part of it.
    Mesh m;
    m.AddQuad({0, 0, 0}, {20, 0, 0}, {0, 10, 0});
    m.AddQuad({0, 0, 8}, {20, 0, 0}, {0, 10, 0});
    m.AddQuad({0, 0, 0}, {20, 0, 0}, {0, 0, 8});
    m.AddQuad({0, 10, 0}, {20, 0, 0}, {0, 0, 8});
    m.AddQuad({0, 0, 0}, {0, 10, 0}, {0, 0, 8});
    m.AddQuad({20, 0, 0}, {0, 10, 0}, {0, 0, 8});
    m.AddQuad({10, 4, 0}, {0, 2, 0}, {0, 0, 8});
    const store::OccupancyGrid grid = store::OccupancyGrid::Of(m.positions, m.indices);
    // Along the room, beside the screen, short of the end wall.
    EXPECT_TRUE(grid.SegmentEmpty({1, 2, 4}, {1, 0, 0}, 0, 18));
    EXPECT_TRUE(grid.SegmentEmpty({1, 2, 4}, Normalize(Vec3f{1, 0.1f, 0.1f}), 0, 15));
    // Into the end wall, into the screen, and grazing the screen's edge at y = 4.
    EXPECT_FALSE(grid.SegmentEmpty({1, 2, 4}, {1, 0, 0}, 0, 19.5f));
    EXPECT_FALSE(grid.SegmentEmpty({1, 5, 4}, {1, 0, 0}, 0, 15));
    EXPECT_FALSE(grid.SegmentEmpty({1, 4, 4}, {1, 0, 0}, 0, 15));
    // Outside the room's box, or before the segment starts: empty.
    EXPECT_TRUE(grid.SegmentEmpty({1, 2, 20}, {1, 0, 0}, 0, 100));
    EXPECT_TRUE(grid.SegmentEmpty({-10, 2, 4}, {-1, 0, 0}, 0, 100));
    // A mesh with no triangles has nothing to meet.
    EXPECT_TRUE(store::OccupancyGrid::Of({}, {}).SegmentEmpty({0, 0, 0}, {1, 0, 0}, 0, 1));
    // An invalid segment is not called empty.
    EXPECT_FALSE(grid.SegmentEmpty({1, 2, 4}, {1, 0, 0}, 5, 1));
}

// A row of four bricks between two walls, the middle two holding only a small box each in a
// corner. A ray along the row's middle crosses them in air: once they have been loaded (their
// grids made), Route sends it past them to the brick of the wall it meets, as a trace that missed
// their meshes would, when skip_air is on and the integrator asked (SkipBricksCrossedInAir);
// otherwise to the first brick on its way. A ray toward a box stops at the box's brick.
TEST(OccupancyGrid, RoutePassesOverBricksCrossedInAir) {
    store::BrickMesh mesh;
    AppendQuad(&mesh, {0, 0.5f, 0.5f}, {0, 0.5f, 0}, {0, 0, 0.5f}, 2, 0);
    AppendQuad(&mesh, {4, 0.5f, 0.5f}, {0, 0, 0.5f}, {0, 0.5f, 0}, 2, 0);
    AppendBox(&mesh, Bounds3f({1.4f, 0.85f, 0.85f}, {1.6f, 0.95f, 0.95f}), 0);
    AppendBox(&mesh, Bounds3f({2.4f, 0.85f, 0.85f}, {2.6f, 0.95f, 0.95f}), 0);
    auto source = testing::GridSource(mesh, testing::NamedMaterials({"wall"}), {4, 1, 1});
    ASSERT_TRUE(source != nullptr);
    ASSERT_EQ(source->brick_count(), 4u);
    // Without skip_air (the default), SkipBricksCrossedInAir changes nothing and loads make no
    // grids.
    std::unique_ptr<StreamScheduler> scheduler;
    {
        auto made = StreamScheduler::Create(*source, PagerOptions(), {}, 1000);
        ASSERT_TRUE(made.ok()) << made.status().ToString();
        scheduler = std::move(*made);
    }
    const auto route = [&](Vec3f origin) {
        RayRecord r{};
        r.origin = origin;
        r.dir = {1, 0, 0};
        r.t_max = 100;
        const uint32_t slot = scheduler->Route(r, 0, store::kNoBrick);
        EXPECT_NE(slot, store::kNoBrick);
        return std::pair{source->cells()[source->BrickOfSlot(slot)], r.t_enter};
    };
    const Vec3f down_the_row{0.5f, 0.3f, 0.3f};
    const auto load_all = [&] {
        for (uint32_t b = 0; b < source->brick_count(); ++b) ASSERT_TRUE(source->Acquire(b).ok());
    };
    scheduler->SkipBricksCrossedInAir();
    load_all();
    for (uint32_t b = 0; b < source->brick_count(); ++b) {
        EXPECT_EQ(source->Occupancy(b), nullptr);
        ASSERT_TRUE(source->Evict(b));
    }
    EXPECT_LT(route(down_the_row).first.max.x, 1.5f);
    scheduler.reset();
    PagerOptions skip_air;
    skip_air.skip_air = PagerOptions::SkipAir::kOn;
    {
        auto made = StreamScheduler::Create(*source, skip_air, {}, 1000);
        ASSERT_TRUE(made.ok()) << made.status().ToString();
        scheduler = std::move(*made);
    }
    scheduler->SkipBricksCrossedInAir();
    EXPECT_LT(route(down_the_row).first.max.x, 1.5f);  // no grids yet
    load_all();
    for (uint32_t b = 0; b < source->brick_count(); ++b) ASSERT_NE(source->Occupancy(b), nullptr);
    // The first brick is crossed in air too (its wall lies behind the origin).
    const auto [cell, t_enter] = route(down_the_row);
    EXPECT_GT(cell.max.x, 3.9f);
    EXPECT_NEAR(down_the_row.x + t_enter, cell.min.x, 1e-5f);
    const auto [box_cell, box_t] = route({0.5f, 0.9f, 0.9f});
    EXPECT_LT(box_cell.min.x, 1.4f);
    EXPECT_GT(box_cell.max.x, 1.6f);
}

}  // namespace
}  // namespace nave::render
