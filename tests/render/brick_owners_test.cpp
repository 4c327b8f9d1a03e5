// Bricks to the ranks of a distributed render (brick_owners.h): every rank gets a run of
// neighbouring bricks of about equal size, every level of a brick goes with it, and every rank
// computes the same.

#include "src/render/stream/brick_owners.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "render_test_util.h"
#include "src/render/stream/stream_scheduler.h"
#include "store/testing/store_testing.h"

namespace nave::render {
namespace {

TEST(BrickOwners, RanksGetRunsOfNeighbouringBricksOfAboutEqualSize) {
    const store::BrickMesh mesh = store::testing::MakeSurface({.quads_x = 128, .quads_y = 128});
    store::LevelOptions levels;
    levels.relative_errors = {0.02};
    levels.border_lock = store::LevelOptions::BorderLock::kNone;
    auto source = testing::GridSourceWithLevels(mesh, testing::NamedMaterials({"a", "b", "c"}),
                                                {4, 4, 1}, levels);
    ASSERT_TRUE(source != nullptr);
    ASSERT_TRUE(source->UseLevels(2).ok());
    ASSERT_EQ(source->level_count(), 2u);
    for (int ranks : {1, 2, 3, 5}) {
        SCOPED_TRACE(::testing::Message() << ranks << " ranks");
        const std::vector<int> owners = BrickOwners(*source, ranks);
        ASSERT_EQ(owners.size(), source->slot_count());
        EXPECT_EQ(owners, BrickOwners(*source, ranks));  // deterministic
        std::vector<double> bytes(size_t(ranks), 0.0);
        double total = 0, largest = 0;
        for (uint32_t s = 0; s < source->slot_count(); ++s) {
            const uint32_t b = source->BrickOfSlot(s);
            ASSERT_GE(owners[s], 0);
            ASSERT_LT(owners[s], ranks);
            EXPECT_EQ(owners[s], owners[b]) << "slot " << s << ": a level away from its brick";
            if (s != b) continue;
            const double size = double(source->EstimatedResidentBytes(b));
            bytes[size_t(owners[b])] += size;
            total += size;
            largest = std::max(largest, size);
        }
        // Each rank's share within a brick of the mean.
        for (int r = 0; r < ranks; ++r)
            EXPECT_NEAR(bytes[size_t(r)], total / ranks, largest) << "rank " << r;
        // Runs in the tree's depth-first order: walking it, the rank never goes back.
        const std::vector<uint32_t> order = BricksDepthFirst(*source);
        ASSERT_EQ(order.size(), source->brick_count());
        EXPECT_EQ(std::set<uint32_t>(order.begin(), order.end()).size(), order.size())
            << "a brick listed twice";
        std::set<int> seen;
        for (size_t i = 0; i < order.size(); ++i) {
            const int r = owners[order[i]];
            if (i > 0 && r != owners[order[i - 1]]) {
                EXPECT_TRUE(seen.insert(owners[order[i - 1]]).second)
                    << "rank " << owners[order[i - 1]] << " owns two runs";
            }
        }
    }
}

// Re-balancing: cut by measured work, a rank whose bricks took most of the time gets fewer of
// them, each rank's share of the work lies within a brick's of the mean, and the runs stay runs.
TEST(BrickOwners, MeasuredWorkCutsRunsOfAboutEqualWork) {
    const store::BrickMesh mesh = store::testing::MakeSurface({.quads_x = 64, .quads_y = 64});
    auto source = testing::GridSource(mesh, testing::NamedMaterials({"a"}), {4, 4, 1});
    ASSERT_TRUE(source != nullptr);
    const uint32_t bricks = source->brick_count();
    // The first rank's bricks by size took ten times longer each than the others.
    const std::vector<int> by_size = BrickOwners(*source, 2);
    std::vector<uint64_t> work(bricks);
    for (uint32_t b = 0; b < bricks; ++b) work[b] = by_size[b] == 0 ? 10000 : 1000;
    const std::vector<int> owners = BrickOwnersByWork(*source, 2, work);
    EXPECT_EQ(owners, BrickOwnersByWork(*source, 2, work));  // deterministic
    std::vector<uint64_t> share(2, 0);
    int rank0_bricks = 0, rank0_before = 0;
    for (uint32_t b = 0; b < bricks; ++b) {
        share[size_t(owners[b])] += work[b];
        rank0_bricks += owners[b] == 0;
        rank0_before += by_size[b] == 0;
    }
    EXPECT_LT(rank0_bricks, rank0_before);
    const uint64_t total = share[0] + share[1];
    for (int r = 0; r < 2; ++r)
        EXPECT_NEAR(double(share[size_t(r)]), double(total) / 2, 10000.0) << "rank " << r;
    // Without measured work, as by size.
    EXPECT_EQ(BrickOwnersByWork(*source, 2, std::vector<uint64_t>(bricks, 0)).size(),
              source->slot_count());
}

// For a trace (bench/replay_mpi.py): the rays a batch sent, per other slot (a brick at a level:
// where every rank holds a coarse level, a ray moving to it from its brick's full mesh stays
// home, and one moving back may not), in slot order.
TEST(SentPerBrick, CountsTheRaysSentToEachOtherSlot) {
    const store::BrickMesh mesh = store::testing::MakeSurface({.quads_x = 64, .quads_y = 64});
    store::LevelOptions levels;
    levels.relative_errors = {0.02};
    levels.border_lock = store::LevelOptions::BorderLock::kNone;
    auto source =
        testing::GridSourceWithLevels(mesh, testing::NamedMaterials({"a"}), {4, 1, 1}, levels);
    ASSERT_TRUE(source != nullptr);
    ASSERT_TRUE(source->UseLevels(2).ok());
    ASSERT_EQ(source->brick_count(), 4u);
    RayOutbox out;
    const RayRecord r{};
    const uint32_t from = source->SlotOf(1, 0);
    for (int i = 0; i < 3; ++i) out.Send(source->SlotOf(2, 0), from, r);
    out.Send(source->SlotOf(2, 1), from, r);  // brick 2 at its coarse level
    out.Send(source->SlotOf(0, 1), from, r);
    out.Send(source->SlotOf(1, 1), from, r);  // its own brick at another level
    SentPerBrick sent;
    EXPECT_EQ(sent.Text(), "");
    sent.Count(from, out);
    // The same rays from a batch of brick 1's coarse level: those to that slot are not moves.
    sent.Count(source->SlotOf(1, 1), out);
    // Slots 2 (brick 2), 4 (brick 0 at level 1), 5 (brick 1 at level 1), 6 (brick 2 at level 1).
    EXPECT_EQ(sent.Text(), "2:6 4:2 5:1 6:2");
}

// The processes above the mean hand a share of the rays entering the slots every process holds to
// those below it: each process then does the mean, where its shared work allows.
TEST(SpreadOfSharedWork, HandsTheExcessToTheProcessesBelowTheMean) {
    // Work made: 6, 1, 3, 2 (mean 3); shared work among it: 4, 0, 1, 2.
    const std::vector<double> made = {6, 1, 3, 2}, shared = {4, 0, 1, 2};
    const std::vector<std::vector<double>> spread = SpreadOfSharedWork(made, shared);
    ASSERT_EQ(spread.size(), 4u);
    // Process 0 hands 3 of its 4 to process 1 (lacks 2) and 3 (lacks 1): 2 and 1.
    EXPECT_DOUBLE_EQ(spread[0][0], 0.25);
    EXPECT_DOUBLE_EQ(spread[0][1], 0.5);
    EXPECT_DOUBLE_EQ(spread[0][2], 0.0);
    EXPECT_DOUBLE_EQ(spread[0][3], 0.25);
    for (size_t r = 1; r < 4; ++r) {
        for (size_t d = 0; d < 4; ++d) EXPECT_DOUBLE_EQ(spread[r][d], r == d ? 1.0 : 0.0);
    }
    std::vector<double> after(4, 0.0);
    for (size_t r = 0; r < 4; ++r) {
        after[r] += made[r] - shared[r];
        for (size_t d = 0; d < 4; ++d) after[d] += shared[r] * spread[r][d];
    }
    for (double a : after) EXPECT_DOUBLE_EQ(a, 3.0);
}

// A process cannot hand on more than its shared work: above the mean with little of it shared, it
// hands all of it and stays above.
TEST(SpreadOfSharedWork, HandsAtMostItsSharedWork) {
    const std::vector<std::vector<double>> spread = SpreadOfSharedWork({8, 0}, {1, 0});
    EXPECT_DOUBLE_EQ(spread[0][0], 0.0);
    EXPECT_DOUBLE_EQ(spread[0][1], 1.0);
    EXPECT_DOUBLE_EQ(spread[1][1], 1.0);
    // Balanced: nobody hands anything.
    const std::vector<std::vector<double>> even = SpreadOfSharedWork({2, 2}, {2, 2});
    EXPECT_DOUBLE_EQ(even[0][0], 1.0);
    EXPECT_DOUBLE_EQ(even[1][1], 1.0);
}

}  // namespace
}  // namespace nave::render
