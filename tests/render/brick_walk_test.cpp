// Tracing across bricks: the t-range acceptance finds the same nearest hit whatever the brick
// count.

#include "src/render/bricks/brick_walk.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "src/render/bricks/brick_source.h"
#include "src/render/bricks/grid_bricks.h"
#include "src/render/bricks/memory_brick_source.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/transport/rng.h"

namespace nave::render {
namespace {

store::BrickMesh TestMesh() {
    store::BrickMesh m;
    AppendSphere(&m, {0, 0, 0}, 1.0f, 24, 48, 0);
    AppendSphere(&m, {0.9f, 0.4f, 0.3f}, 0.35f, 12, 24, 1);
    AppendQuad(&m, {0, 0, -1.2f}, {3, 0, 0}, {0, 3, 0}, 7, 2);
    AppendBox(&m, Bounds3f({-2.5f, 1.2f, -1.1f}, {-1.6f, 2.1f, 0.5f}), 3);
    return m;
}

std::shared_ptr<EmbreeDevice> Device() {
    auto d = EmbreeDevice::Create();
    EXPECT_TRUE(d.ok()) << d.status().ToString();
    return *d;
}

TEST(SplitIntoGridBricks, EveryTriangleLandsInEveryOverlappedCell) {
    store::BrickMesh mesh = TestMesh();
    GridBricks grid = SplitIntoGridBricks(mesh, 4, 4, 4);
    ASSERT_TRUE(grid.tree.Validate(uint32_t(grid.meshes.size())).ok());
    size_t total = 0;
    for (const auto& m : grid.meshes) total += m.TriangleCount();
    EXPECT_GT(total, mesh.TriangleCount());  // triangles crossing cells are duplicated
    std::vector<Bounds3f> cells = grid.tree.BrickCells(uint32_t(grid.meshes.size()));
    for (size_t b = 0; b < grid.meshes.size(); ++b) {
        for (size_t t = 0; t < grid.meshes[b].TriangleCount(); ++t) {
            Bounds3f tb;
            for (int c = 0; c < 3; ++c)
                tb.Extend(grid.meshes[b].positions[grid.meshes[b].indices[3 * t + c]]);
            EXPECT_TRUE(tb.Overlaps(cells[b])) << "brick " << b << " triangle " << t;
        }
    }
}

TEST(TraceNearest, SameHitsWithOneAnd64Bricks) {
    auto device = Device();
    store::BrickMesh mesh = TestMesh();
    GridBricks one = SplitIntoGridBricks(mesh, 1, 1, 1);
    GridBricks many = SplitIntoGridBricks(mesh, 4, 4, 4);
    MemoryBrickSource src1(device, one.tree, one.meshes, {});
    MemoryBrickSource src64(device, many.tree, many.meshes, {});
    ASSERT_GT(src64.brick_count(), 30u);
    int hits = 0, mismatches = 0;
    const int kRays = 20000;
    for (int i = 0; i < kRays; ++i) {
        VertexRng rng(RngKey{7, uint32_t(i)});
        Vec3f o(6 * rng.Uniform(0) - 3, 6 * rng.Uniform(1) - 3, 3 * rng.Uniform(2) - 1.5f);
        float z = 2 * rng.Uniform(3) - 1, phi = 6.2831853f * rng.Uniform(4);
        float s = std::sqrt(std::max(0.f, 1 - z * z));
        Vec3f d(s * std::cos(phi), s * std::sin(phi), z);
        BrickHit h1, h64;
        uint32_t b1, b64;
        auto r1 = TraceNearest(src1, o, d, 0, 1e30f, &h1, &b1);
        auto r64 = TraceNearest(src64, o, d, 0, 1e30f, &h64, &b64);
        ASSERT_TRUE(r1.ok() && r64.ok());
        ASSERT_EQ(*r1, *r64) << "ray " << i;
        if (!*r1) continue;
        ++hits;
        // Same triangle: same material and the same t to float precision.
        uint32_t m1 = one.meshes[b1].material_ids[h1.triangle];
        uint32_t m64 = many.meshes[b64].material_ids[h64.triangle];
        if (m1 != m64 || std::abs(h1.t - h64.t) > 1e-5f * (1 + h1.t)) {
            ++mismatches;
            ADD_FAILURE() << "ray " << i << " t " << h1.t << " vs " << h64.t << " material " << m1
                          << " vs " << m64;
        }
    }
    EXPECT_GT(hits, kRays / 4);
    EXPECT_EQ(mismatches, 0);
    EXPECT_EQ(src64.stats().loads, src64.brick_count());  // every brick was visited at least once
}

TEST(BrickSource, PinsAndEvicts) {
    auto device = Device();
    GridBricks grid = SplitIntoGridBricks(TestMesh(), 2, 2, 2);
    MemoryBrickSource src(device, grid.tree, grid.meshes, {});
    ASSERT_FALSE(src.IsResident(0));
    {
        auto h = src.Acquire(0);
        ASSERT_TRUE(h.ok());
        EXPECT_TRUE(src.IsResident(0));
        EXPECT_FALSE(src.Evict(0));  // pinned
    }
    EXPECT_TRUE(src.Evict(0));
    EXPECT_FALSE(src.IsResident(0));
    auto again = src.Acquire(0);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(src.stats().loads, 2u);
    EXPECT_EQ(src.stats().evictions, 1u);
    auto bad = src.Acquire(src.brick_count());
    EXPECT_FALSE(bad.ok());
}

// Readers pin bricks while another thread evicts whatever is not pinned: a pinned brick stays in
// memory and is the brick asked for until its pin goes (under the asan preset, a brick freed while
// pinned is a use after free here).
TEST(BrickSource, ConcurrentPinsNeverLoseTheirBrick) {
    auto device = Device();
    GridBricks grid = SplitIntoGridBricks(TestMesh(), 2, 2, 2);
    MemoryBrickSource src(device, grid.tree, grid.meshes, {});
    const uint32_t bricks = src.brick_count();
    std::atomic<bool> stop{false};
    std::atomic<uint64_t> evictions{0};
    std::thread evictor([&] {
        for (uint32_t i = 0; !stop.load(); ++i) {
            if (src.Evict(i % bricks)) evictions.fetch_add(1);
        }
    });
    // Each reader pins at least kPins times and goes on until the evictor has taken bricks away
    // often enough to meet the readers' reloads (two cores may run the three threads in turns).
    constexpr int kReaders = 2, kPins = 4000;
    constexpr uint64_t kMinEvictions = 500;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    std::atomic<int> wrong{0};
    std::vector<std::thread> readers;
    readers.reserve(kReaders);
    for (int t = 0; t < kReaders; ++t) {
        readers.emplace_back([&, t] {
            for (int i = 0; i < kPins || (evictions.load() < kMinEvictions &&
                                          std::chrono::steady_clock::now() < deadline);
                 ++i) {
                const uint32_t id = uint32_t(i * 7 + t) % bricks;
                StatusOr<BrickHandle> h = src.Acquire(id);
                // (IsResident may say no for a moment meanwhile: an evictor that found the brick
                // pinned on its second look puts it back.)
                if (!h.ok() || (*h)->id() != id ||
                    (*h)->mesh().TriangleCount() != grid.meshes[id].TriangleCount()) {
                    wrong.fetch_add(1);
                }
            }
        });
    }
    for (std::thread& r : readers) r.join();
    stop.store(true);
    evictor.join();
    EXPECT_EQ(wrong.load(), 0);
    EXPECT_GE(evictions.load(), kMinEvictions);  // the evictor took bricks between the pins
    EXPECT_EQ(src.stats().evictions, evictions.load());
    EXPECT_EQ(
        src.stats().loads, src.stats().evictions + [&] {
            uint64_t resident = 0;
            for (uint32_t b = 0; b < bricks; ++b) resident += src.IsResident(b) ? 1 : 0;
            return resident;
        }());
}

}  // namespace
}  // namespace nave::render
