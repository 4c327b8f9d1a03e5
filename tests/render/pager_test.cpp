// The out-of-core pager: a render under a small brick budget gives the image of an in-core render,
// never holds more than the budget, evicts and reloads at small budgets and not at an in-core one,
// refuses an impossible budget naming the largest brick, and returns a corrupt brick's error when
// it meets it.

#include "src/render/stream/pager.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>

#include "common/file_size_limit.h"
#include "common/run_nave.h"
#include "pager_test_scene.h"
#include "render_test_util.h"
#include "src/core/memory.h"
#include "src/core/progress.h"
#include "src/render/bricks/memory_brick_source.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/bricks/store_brick_source.h"
#include "src/render/stream/memory_plan.h"
#include "src/render/stream/ray.h"
#include "src/render/stream/stream_scheduler.h"
#include "store/store_reader.h"

namespace nave::render {
namespace {

using testing::BuildAndRender;
using testing::BuildTestScene;
using testing::MaxRelativeDifference;
using testing::MeanY;
using testing::RenderResult;
using testing::RunOptions;
using testing::TestRender;

class PagerTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

// A floor with a 4 x 4 grid of balls, cut into 4 x 4 x 2 bricks: one ball per brick, so the largest
// bricks are about 1/16 of the model and a budget of ~15 % of the in-core size is feasible. Ball
// (0, 0) glows (photon mode then reads every brick to find its triangles).
store::BrickMesh BallGrid() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 6, 0);
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
            AppendSphere(&m, {-3 + 2.f * float(i), -3 + 2.f * float(j), 0.7f}, 0.6f, 16, 32,
                         i == 0 && j == 0 ? 2 : 1);
        }
    }
    return m;
}

/// A fresh source over the ball grid (fresh so that its own peak counter covers this render only).
std::unique_ptr<BrickSource> BallGridSource() {
    return testing::GridSource(BallGrid(), testing::NamedMaterials(kNames), {4, 4, 2});
}

/// The ball grid's config in `mode` (path, photon, "photon_gather": photon with final gathering
/// and its guide, "path_guided": path guiding over 16 passes, "path_haze" and "photon_haze": with a
/// medium over the model, or "path_water" and "photon_water": balls of water that scatters, in
/// that haze; "path_glow": the water and the haze glow; "path_air": path mode over bricks whose
/// occupancy grids are known, so that rays pass over the bricks they cross in air).
SceneConfig BallGridConfig(const std::string& mode) {
    const bool gather = mode == "photon_gather", guided = mode == "path_guided",
               glow = mode == "path_glow",
               water = mode == "path_water" || mode == "photon_water" || glow,
               haze = mode == "path_haze" || mode == "photon_haze" || water;
    const std::string base = mode.starts_with("photon") ? "photon" : "path";
    const std::string text = fmt::format(fmt::runtime(kBallGrid), base) +
                             (haze ? "[medium]\nsigma_s = 0.2\nsigma_a = 0.02\ng = 0.5\n" : "") +
                             (glow ? "emission = 0.5\n" : "");
    auto config = ParseSceneConfig(text, "balls.toml");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    if (!config.ok()) return SceneConfig();
    config->render.final_gather = gather;
    if (water) {
        MaterialConfig& ball = config->materials["ball"];
        ball = MaterialConfig();
        ball.kind = MaterialConfig::Kind::kDielectric;
        ball.eta = SpectrumSpec::Constant(1.33f);
        ball.medium = MediumConfig();
        ball.medium->name = "materials.ball.medium";
        ball.medium->sigma_s = SpectrumSpec::Constant(2.f);
        ball.medium->sigma_a = SpectrumSpec::Constant(0.3f);
        ball.medium->g = 0.3f;
        if (glow) ball.medium->emission = SpectrumSpec::Constant(0.2f);
    }
    if (guided) {
        // Rounds 0-1 | 2-3 | 4-7 | ... | 32-63: passes 4-63 sample what rounds 0-3 taught.
        config->render.path_guiding = true;
        config->render.spp = 64;
    }
    return *config;
}

/// The ball grid rendered on a fresh source; the render's Status is kept, not expected. Null if
/// the scene could not be built (the test has failed then).
std::unique_ptr<TestRender> RenderBallGrid(const std::string& mode, const PagerOptions* paging,
                                           int threads = 2, uint32_t wave_paths = 0, int spp = 0) {
    SceneConfig config = BallGridConfig(mode);
    config.render.threads = threads;
    if (wave_paths > 0) config.render.wave_paths = wave_paths;
    if (spp > 0) config.render.spp = spp;
    RunOptions run;
    run.paging = paging;
    std::unique_ptr<BrickSource> source = BallGridSource();
    // "path_air": every brick's occupancy grid known from the start, as a store holds them.
    if (mode == "path_air") static_cast<MemoryBrickSource&>(*source).KnowOccupancy();
    return BuildAndRender(std::move(source), std::move(config), run);
}

/// A budget of about 15 % of the in-core size, or the minimum if that is more.
PagerOptions SmallBudget(const BrickSource& source, bool prefetch = true) {
    BrickBudgetMinimum m = MinimumBrickBudget(source, prefetch);
    PagerOptions o;
    o.prefetch = prefetch;
    o.brick_budget_bytes = std::max(m.min_bytes, m.total_bytes * 15 / 100);
    o.spill_dir = std::filesystem::temp_directory_path();
    return o;
}

void ExpectPagedEqualsInCore(const std::string& mode, double bound) {
    const auto in_core = RenderBallGrid(mode, nullptr);
    ASSERT_TRUE(in_core != nullptr);
    ASSERT_TRUE(in_core->status.ok()) << in_core->status.ToString();
    const BrickBudgetMinimum m = MinimumBrickBudget(*in_core->source, true);
    EXPECT_GE(in_core->source->brick_count(), 30u);
    EXPECT_EQ(in_core->stats.rounds_overlapped, 0) << "in-core, every wave is drained";
    int rounds_overlapped = 0;
    // Prefetching on and off; then small waves (the in-core render has one), which under paging
    // overlap; then without the brick cache (every reload decodes the brick again); then with
    // queues spilled to disk beyond 64 KiB.
    for (int variant = 0; variant < 5; ++variant) {
        // A guided render takes 64 passes to guide at all: prefetching on and small waves are its
        // variants (the others' paging does not depend on the mode), which keeps it within the
        // ThreadSanitizer suite's time.
        if (mode == "path_guided" && variant != 0 && variant != 2) continue;
        const bool prefetch = variant != 1;
        const uint32_t wave_paths = variant == 2 ? 500 : 0;
        PagerOptions options = SmallBudget(*in_core->source, prefetch);
        options.brick_cache = variant != 3;
        if (variant == 4) options.queue_memory_bytes = 64 << 10;
        EXPECT_LE(options.brick_budget_bytes, m.total_bytes / 4)
            << "the test scene should allow a small budget";
        const auto paged = RenderBallGrid(mode, &options, 2, wave_paths);
        ASSERT_TRUE(paged != nullptr);
        ASSERT_TRUE(paged->status.ok()) << paged->status.ToString();
        EXPECT_GT(MeanY(*paged->film), 0.0);
        // Same bounds as the brick-count and brick-order tests (render_test.cpp): both modes differ
        // only by the order of double sums (the film's; the photons' flux at a pixel).
        EXPECT_LT(MaxRelativeDifference(*in_core->film, *paged->film), bound)
            << mode << " variant " << variant;
        // The budget holds, by the pager's count and by the source's own.
        EXPECT_LE(paged->stats.residency.peak_resident_bytes, options.brick_budget_bytes);
        EXPECT_LE(paged->source->stats().peak_resident_bytes, options.brick_budget_bytes);
        EXPECT_GT(paged->stats.residency.evictions, 0u);
        EXPECT_GT(paged->stats.residency.reloads, 0u);
        EXPECT_GT(paged->stats.residency.loads, in_core->stats.residency.loads);
        EXPECT_EQ(paged->stats.residency.prefetch_loads > 0, prefetch);
        EXPECT_EQ(paged->stats.residency.brick_budget_bytes, options.brick_budget_bytes);
        EXPECT_EQ(paged->stats.spilled_rays > 0, variant == 4) << variant;
        rounds_overlapped += paged->stats.rounds_overlapped;
        // With the cache, every brick is decoded once and every reload read back from it.
        if (options.brick_cache) {
            EXPECT_EQ(paged->stats.brick_cache_reads, paged->stats.residency.reloads) << variant;
            EXPECT_EQ(paged->stats.brick_cache_written + paged->stats.residency.reloads,
                      paged->stats.residency.loads)
                << variant;
        } else {
            EXPECT_EQ(paged->stats.brick_cache_reads, 0u);
            EXPECT_EQ(paged->stats.brick_cache_written, 0u);
        }
    }
    // A guided render's rounds begin while the round before is still in flight under a budget:
    // the same image says that what each pass sampled did not depend on it.
    if (mode == "path_guided") {
        EXPECT_GT(in_core->stats.guide_cells_guiding, 0u);
        EXPECT_GT(rounds_overlapped, 0);
    }
}

TEST_F(PagerTest, AWaveLargerThanTheQueueMemorySpillsAsItIsGenerated) {
    // 32x24 pixels at 64 spp in one wave: 49 152 camera paths, 5.3 MiB of records, where the queues
    // may hold 64 KiB and what the reserve allows beyond (RenderReserveBytes).
    const auto in_core = RenderBallGrid("path", nullptr, 2, 1 << 20, 64);
    ASSERT_TRUE(in_core != nullptr);
    ASSERT_TRUE(in_core->status.ok()) << in_core->status.ToString();
    PagerOptions options = SmallBudget(*in_core->source);
    options.queue_memory_bytes = 64 << 10;
    const auto paged = RenderBallGrid("path", &options, 2, 1 << 20, 64);
    ASSERT_TRUE(paged != nullptr);
    ASSERT_TRUE(paged->status.ok()) << paged->status.ToString();
    const uint64_t bound = options.queue_memory_bytes +
                           3 * MaxBatchRays(options.queue_memory_bytes) * sizeof(RayRecord);
    ASSERT_GT(paged->stats.camera_paths * sizeof(RayRecord), 2 * bound)
        << "the wave should exceed the bound";
    EXPECT_LE(paged->stats.peak_queue_bytes, bound);
    EXPECT_GT(paged->stats.spilled_rays, paged->stats.camera_paths / 2);
    EXPECT_LT(MaxRelativeDifference(*in_core->film, *paged->film), 1e-9);
}

TEST_F(PagerTest, PagedRenderEqualsInCorePath) { ExpectPagedEqualsInCore("path", 1e-9); }
TEST_F(PagerTest, PagedRenderEqualsInCoreGuidedPath) {
    ExpectPagedEqualsInCore("path_guided", 1e-9);
}

// A medium's scatterings happen in whichever brick a ray's free flight ends, resident or not.
TEST_F(PagerTest, PagedRenderEqualsInCorePathInHaze) { ExpectPagedEqualsInCore("path_haze", 1e-9); }

// Photons too scatter in whichever brick their flight ends.
TEST_F(PagerTest, PagedRenderEqualsInCorePhotonInHaze) {
    ExpectPagedEqualsInCore("photon_haze", 1e-9);
}

TEST_F(PagerTest, PagedRenderEqualsInCoreThroughBallsOfWater) {
    ExpectPagedEqualsInCore("path_water", 1e-9);
    ExpectPagedEqualsInCore("photon_water", 1e-9);
}

// What media emit is gathered along each flight where it crosses a brick, resident or not.
TEST_F(PagerTest, PagedRenderEqualsInCoreInGlowingMedia) {
    ExpectPagedEqualsInCore("path_glow", 1e-9);
}

// With every brick's occupancy grid known from the start (a store's, format 3.4), rays pass over
// the bricks they cross in air the same way whatever the budget: the paged image is the in-core
// one, and the rays did pass over bricks.
TEST_F(PagerTest, PagedRenderEqualsInCoreWhenRaysPassOverBricksInAir) {
    ExpectPagedEqualsInCore("path_air", 1e-9);
    const auto over = RenderBallGrid("path_air", nullptr);
    const auto through = RenderBallGrid("path", nullptr);
    ASSERT_TRUE(over && through);
    EXPECT_TRUE(over->source->occupancy_known());
    EXPECT_FALSE(through->source->occupancy_known());
    EXPECT_LT(over->stats.brick_moves, through->stats.brick_moves);
    EXPECT_LT(over->stats.segments_traced, through->stats.segments_traced);
    // The same surfaces met: the same image but for the order of the film's sums.
    EXPECT_LT(MaxRelativeDifference(*over->film, *through->film), 1e-4);
}

TEST_F(PagerTest, PagedRenderEqualsInCorePhoton) { ExpectPagedEqualsInCore("photon", 1e-9); }

TEST_F(PagerTest, PagedRenderEqualsInCorePhotonWithFinalGather) {
    ExpectPagedEqualsInCore("photon_gather", 1e-9);
}

TEST_F(PagerTest, InCoreBudgetLoadsEveryBrickOnceAndEvictsNothing) {
    const auto in_core = RenderBallGrid("path", nullptr);
    ASSERT_TRUE(in_core != nullptr);
    ASSERT_TRUE(in_core->status.ok());
    PagerOptions options;
    options.brick_budget_bytes = MinimumBrickBudget(*in_core->source, true).total_bytes;
    const auto paged = RenderBallGrid("path", &options);
    ASSERT_TRUE(paged != nullptr);
    ASSERT_TRUE(paged->status.ok()) << paged->status.ToString();
    EXPECT_EQ(paged->stats.residency.evictions, 0u);
    EXPECT_EQ(paged->stats.residency.reloads, 0u);
    EXPECT_EQ(paged->stats.residency.loads, in_core->stats.residency.loads);
    EXPECT_LT(MaxRelativeDifference(*in_core->film, *paged->film), 1e-9);
}

TEST_F(PagerTest, FreePagesGoBackAtBatchEndsNearTheProcessLimitAlsoWithoutLoads) {
    // Every brick fits, so the loads end early; a process limit below the resident size makes
    // every check return pages: more returns than loads means batch ends check too.
    PagerOptions options;
    options.memory_bytes = 1;
    const auto paged = RenderBallGrid("path", &options);
    ASSERT_TRUE(paged != nullptr);
    ASSERT_TRUE(paged->status.ok()) << paged->status.ToString();
    EXPECT_EQ(paged->stats.residency.evictions, 0u);
    EXPECT_GT(paged->stats.residency.memory_returns, paged->stats.residency.loads);
}

TEST_F(PagerTest, CustomPickerWithPagingRendersTheSameImage) {
    // Emptiest brick first: the worst order for paging, still the same image within budget.
    const auto in_core = RenderBallGrid("path", nullptr);
    ASSERT_TRUE(in_core != nullptr);
    ASSERT_TRUE(in_core->status.ok());
    auto scene = BuildTestScene(BallGridSource(), BallGridConfig("path"));
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    const BrickSource& source = *(*scene)->source;
    PagerOptions options = SmallBudget(source);
    RunOptions run;
    run.paging = &options;
    run.picker = [](const std::vector<size_t>& waiting, const BrickSource&) {
        uint32_t best = store::kNoBrick;
        for (uint32_t b = 0; b < waiting.size(); ++b) {
            if (waiting[b] > 0 && (best == store::kNoBrick || waiting[b] < waiting[best])) best = b;
        }
        return best;
    };
    const RenderResult paged = (*scene)->Run(run);
    ASSERT_TRUE(paged.status.ok());
    EXPECT_LT(MaxRelativeDifference(*in_core->film, *paged.film), 1e-9);
    EXPECT_LE(source.stats().peak_resident_bytes, options.brick_budget_bytes);
}

TEST_F(PagerTest, ImpossibleBudgetNamesTheLargestBrickAndTheMinimum) {
    auto source = BallGridSource();
    const BrickBudgetMinimum m = MinimumBrickBudget(*source, true);
    // The estimates are the real sizes: the largest brick is the one the message names.
    uint64_t largest = 0;
    for (uint32_t b = 0; b < source->brick_count(); ++b) {
        largest = std::max(largest, source->EstimatedResidentBytes(b));
    }
    EXPECT_EQ(m.largest_bytes, largest);
    EXPECT_EQ(source->EstimatedResidentBytes(m.largest_brick), largest);
    EXPECT_GT(m.second_bytes, 0u);
    EXPECT_LE(m.second_bytes, m.largest_bytes);
    EXPECT_EQ(m.min_bytes, m.largest_bytes + m.second_bytes);
    PagerOptions options;
    options.brick_budget_bytes = m.min_bytes - 1;
    auto pager = Pager::Create(*source, options, {});
    ASSERT_FALSE(pager.ok());
    const std::string& msg = pager.status().message();
    EXPECT_NE(msg.find(fmt::format("brick {}", m.largest_brick)), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::to_string(m.largest_bytes) + " bytes"), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::to_string(m.min_bytes) + " bytes"), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::to_string(options.brick_budget_bytes) + " bytes"), std::string::npos)
        << msg;
    // Without prefetching the largest brick alone is the minimum.
    options.prefetch = false;
    options.brick_budget_bytes = m.largest_bytes;
    EXPECT_TRUE(Pager::Create(*source, options, {}).ok());
    // RenderStreams refuses it before tracing anything.
    options.prefetch = true;
    const auto r = RenderBallGrid("path", &options);
    ASSERT_TRUE(r != nullptr);
    EXPECT_FALSE(r->status.ok());
    EXPECT_EQ(r->stats.rays, 0u);
    EXPECT_EQ(r->source->stats().loads, 0u);
}

TEST_F(PagerTest, EstimatesMatchTheRealSizes) {
    auto source = BallGridSource();
    for (uint32_t b = 0; b < source->brick_count(); ++b) {
        auto h = source->Acquire(b);
        ASSERT_TRUE(h.ok());
        EXPECT_EQ((*h)->memory_bytes(), source->EstimatedResidentBytes(b)) << "brick " << b;
    }
}

// A pass over the model (the sky's portals, the light sources) visits every brick once, in order,
// with the loaders fetching the next ones, in-core and under the smallest budget; a visit's error
// ends it.
TEST_F(PagerTest, ForEachBrickVisitsEveryBrickInOrderWithTheLoadersAhead) {
    for (const bool tight : {false, true}) {
        SCOPED_TRACE(tight ? "smallest budget" : "in-core");
        auto source = BallGridSource();
        PagerOptions options;
        if (tight) options.brick_budget_bytes = MinimumBrickBudget(*source, true).min_bytes;
        auto scheduler = StreamScheduler::Create(*source, options, {}, 1000);
        ASSERT_TRUE(scheduler.ok()) << scheduler.status().ToString();
        std::vector<uint32_t> visited;
        const Status pass =
            (*scheduler)
                ->ForEachBrick(
                    "test pass", ScanDetail::kFull, [&](uint32_t b, const ResidentBrick& brick) {
                        visited.push_back(b);
                        EXPECT_EQ(brick.memory_bytes(), source->EstimatedResidentBytes(b));
                        // A visit that takes a while, as a real one does: the loaders get ahead
                        // even when other processes keep the cores busy.
                        std::this_thread::sleep_for(std::chrono::milliseconds(5));
                        return Status::Ok();
                    });
        ASSERT_TRUE(pass.ok()) << pass.ToString();
        std::vector<uint32_t> in_order(source->brick_count());
        std::iota(in_order.begin(), in_order.end(), 0u);
        EXPECT_EQ(visited, in_order);
        StreamStats stats;
        (*scheduler)->FillStats(BrickSourceStats(), &stats);
        EXPECT_GT(stats.residency.prefetch_loads, 0u);  // the loaders were ahead
        if (tight) {
            EXPECT_LE(stats.residency.peak_resident_bytes, options.brick_budget_bytes);
        } else {
            EXPECT_EQ(stats.residency.loads, source->brick_count());
        }
    }
    auto source = BallGridSource();
    auto scheduler = StreamScheduler::Create(*source, PagerOptions(), {}, 1000);
    ASSERT_TRUE(scheduler.ok());
    uint32_t last = 0;
    const Status stopped =
        (*scheduler)
            ->ForEachBrick("test pass", ScanDetail::kFull, [&](uint32_t b, const ResidentBrick&) {
                last = b;
                return b == 3 ? DataLossError("brick {} refused", b) : Status::Ok();
            });
    EXPECT_EQ(stopped.code(), StatusCode::kDataLoss);
    EXPECT_EQ(last, 3u);
}

// The largest bricks of the ball grid that share one estimated size, at least four of them (balls
// (1, 1), (1, 2), (2, 1), (2, 2) have the same triangles): two of them make a budget that passes
// the pager's minimum.
std::vector<uint32_t> BricksOfOneSize(const BrickSource& source) {
    std::map<uint64_t, std::vector<uint32_t>> by_size;
    for (uint32_t b = 0; b < source.brick_count(); ++b)
        by_size[source.EstimatedResidentBytes(b)].push_back(b);
    std::vector<uint32_t> same;
    for (const auto& [bytes, ids] : by_size) {
        if (ids.size() >= 4) same = ids;
    }
    return same;
}

// Eviction order: emptiest queue first, least recently used on ties; pinned bricks stay.
TEST_F(PagerTest, EvictsEmptiestThenLeastRecentlyUsedAndNeverPinned) {
    auto source = BallGridSource();
    const std::vector<uint32_t> same = BricksOfOneSize(*source);
    ASSERT_GE(same.size(), 4u);
    const uint64_t size = source->EstimatedResidentBytes(same[0]);
    std::vector<size_t> waiting(source->brick_count(), 0);
    PagerOptions options;
    options.prefetch = false;
    options.brick_budget_bytes = 3 * size;
    auto pager = Pager::Create(*source, options, [&](uint32_t b) { return waiting[b]; });
    ASSERT_TRUE(pager.ok()) << pager.status().ToString();
    const uint32_t a = same[0], b = same[1], c = same[2], d = same[3];
    for (uint32_t id : {a, b, c})
        ASSERT_TRUE((*pager)->Acquire(id).ok());  // handles dropped at once
    waiting[a] = 10;
    waiting[b] = 5;
    waiting[c] = 10;
    // d needs room: b has the fewest rays waiting.
    {
        auto h = (*pager)->Acquire(d);
        ASSERT_TRUE(h.ok());
        EXPECT_FALSE(source->IsResident(b));
        EXPECT_TRUE(source->IsResident(a) && source->IsResident(c));
        // b back: a and c tie on rays, a was used longest ago. d is pinned and stays.
        waiting[d] = 0;
        ASSERT_TRUE((*pager)->Acquire(b).ok());
        EXPECT_FALSE(source->IsResident(a));
        EXPECT_TRUE(source->IsResident(c) && source->IsResident(d));
        // Pin b and c as well: nothing can make room for a.
        auto hb = (*pager)->Acquire(b);
        auto hc = (*pager)->Acquire(c);
        ASSERT_TRUE(hb.ok() && hc.ok());
        auto ha = (*pager)->Acquire(a);
        ASSERT_FALSE(ha.ok());
        EXPECT_EQ(ha.status().code(), StatusCode::kResourceExhausted);
    }
    const PagerStats s = (*pager)->stats();
    EXPECT_EQ(s.evictions, 2u);
    EXPECT_EQ(s.loads, 5u);
    EXPECT_EQ(s.reloads, 1u);
    EXPECT_LE(s.peak_resident_bytes, options.brick_budget_bytes);
}

// What a loader prefetched stays until the scheduler has traced it, unless the brick a prefetch
// makes room for has more rays waiting: two loaders otherwise took turns loading and evicting the
// same nearly empty bricks. The scheduler's own loads may evict any unpinned brick.
TEST_F(PagerTest, APrefetchKeepsAFreshBrickForABrickWithNoMoreRays) {
    auto source = BallGridSource();
    const std::vector<uint32_t> same = BricksOfOneSize(*source);
    ASSERT_GE(same.size(), 4u);
    const uint32_t a = same[0], b = same[1], c = same[2], d = same[3];
    std::mutex mutex;  // the loader reads the queues too
    std::vector<size_t> waiting(source->brick_count(), 0);
    PagerOptions options;
    options.loaders = 1;
    options.brick_budget_bytes = 2 * source->EstimatedResidentBytes(a);
    auto pager = Pager::Create(*source, options, [&](uint32_t id) {
        std::lock_guard<std::mutex> lock(mutex);
        return waiting[id];
    });
    ASSERT_TRUE(pager.ok()) << pager.status().ToString();
    auto set_waiting = [&](uint32_t id, size_t rays) {
        std::lock_guard<std::mutex> lock(mutex);
        waiting[id] = rays;
    };
    // The scheduler's view for a prefetch names one brick, so that the loader loads that one.
    auto prefetch = [&](uint32_t id, size_t rays) {
        set_waiting(id, rays);
        std::vector<size_t> view(waiting.size(), 0);
        view[id] = rays;
        (*pager)->Prefetch(view, store::kNoBrick, 0);
    };
    auto resident_soon = [&](uint32_t id) {
        for (int i = 0; i < 2000 && !source->IsResident(id); ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        return source->IsResident(id);
    };
    ASSERT_TRUE((*pager)->Acquire(a).ok());  // traced by the scheduler, then unpinned
    set_waiting(a, 100);                     // every queue here is nearly empty
    prefetch(b, 50);
    ASSERT_TRUE(resident_soon(b));
    // c (40 rays) needs room: b is emptier than a but fresh, with more rays than c.
    prefetch(c, 40);
    ASSERT_TRUE(resident_soon(c));
    EXPECT_FALSE(source->IsResident(a));
    EXPECT_TRUE(source->IsResident(b));
    // d (45 rays) may evict the fresh c (40), not b (50).
    set_waiting(a, 0);
    prefetch(d, 45);
    ASSERT_TRUE(resident_soon(d));
    EXPECT_FALSE(source->IsResident(c));
    EXPECT_TRUE(source->IsResident(b));
    // c again, with fewer rays than either fresh brick: the loader waits instead of taking turns
    // with itself.
    prefetch(c, 40);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_FALSE(source->IsResident(c));
    EXPECT_TRUE(source->IsResident(b) && source->IsResident(d));
    // The scheduler traces b: at the batch's end the loader may evict it for c.
    ASSERT_TRUE((*pager)->Acquire(b).ok());
    (*pager)->BatchDone();
    ASSERT_TRUE(resident_soon(c));
    EXPECT_FALSE(source->IsResident(b));
    EXPECT_TRUE(source->IsResident(d));
    // A load the scheduler cannot avoid evicts a fresh brick all the same.
    ASSERT_TRUE((*pager)->Acquire(a).ok());
    EXPECT_TRUE(source->IsResident(a));
    EXPECT_LE((*pager)->stats().peak_resident_bytes, options.brick_budget_bytes);
}

TEST_F(PagerTest, PickPrefersAResidentBrickWithEnoughRays) {
    auto source = BallGridSource();
    PagerOptions options;
    options.prefetch = false;
    options.brick_budget_bytes = MinimumBrickBudget(*source, false).total_bytes;
    options.prefer_resident = 0.25;
    auto pager = Pager::Create(*source, options, {});
    ASSERT_TRUE(pager.ok());
    ASSERT_TRUE((*pager)->Acquire(3).ok());
    std::vector<size_t> waiting(source->brick_count(), 0);
    waiting[3] = 30;
    waiting[7] = 100;
    EXPECT_EQ((*pager)->Pick(waiting), 3u);  // resident, 30 % of the fullest's rays
    waiting[3] = 20;
    EXPECT_EQ((*pager)->Pick(waiting), 7u);  // too few: load the fullest
    ASSERT_TRUE((*pager)->Acquire(7).ok());
    waiting[3] = 99;
    EXPECT_EQ((*pager)->Pick(waiting), 7u);  // the fullest is resident
}

TEST_F(PagerTest, TunablesParseAndBadOnesAreNamed) {
    PagerOptions o;
    ASSERT_TRUE(
        ParsePagerTunables(
            "prefetch=off,nearly_empty_rays=100,prefer_resident=0.5,evict=traffic,wave_overlap=0",
            &o)
            .ok());
    EXPECT_FALSE(o.prefetch);
    EXPECT_EQ(o.evict, PagerOptions::Evict::kTraffic);
    EXPECT_EQ(o.wave_overlap, 0.0);
    EXPECT_EQ(o.nearly_empty_rays, 100u);
    EXPECT_DOUBLE_EQ(o.prefer_resident, 0.5);
    ASSERT_TRUE(ParsePagerTunables("", &o).ok());
    EXPECT_EQ(o.skip_air, PagerOptions::SkipAir::kAuto);
    ASSERT_TRUE(ParsePagerTunables("brick_cache=off,brick_cache_limit=3G,skip_air=on", &o).ok());
    EXPECT_EQ(o.skip_air, PagerOptions::SkipAir::kOn);
    ASSERT_TRUE(ParsePagerTunables("skip_air=off", &o).ok());
    EXPECT_EQ(o.skip_air, PagerOptions::SkipAir::kOff);
    EXPECT_FALSE(o.brick_cache);
    EXPECT_EQ(o.brick_cache_limit_bytes, uint64_t(3) << 30);
    for (const char* bad : {"prefetch=maybe", "nearly_empty_rays=-3", "prefer_resident=x",
                            "speed=11", "prefetch", "evict=random", "wave_overlap=2",
                            "brick_cache=yes", "brick_cache_limit=lots", "skip_air=1"}) {
        Status s = ParsePagerTunables(bad, &o);
        EXPECT_FALSE(s.ok()) << bad;
        const std::string key = std::string(bad).substr(0, std::string(bad).find('='));
        EXPECT_NE(s.message().find(key), std::string::npos) << s.message();
    }
}

class PagerStoreTest : public PagerTest {
  protected:
    void SetUp() override {
        PagerTest::SetUp();
        dir_ = std::filesystem::temp_directory_path() / fmt::format("nave_pager_test_{}", getpid());
        std::filesystem::create_directories(dir_);
        path_ = dir_ / "balls.nave";
        Status s = testing::WriteGridBricksStore(path_, BallGrid(), kNames, {4, 4, 2});
        ASSERT_TRUE(s.ok()) << s.ToString();
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path dir_, path_;
};

TEST_F(PagerStoreTest, StoreEstimatesMatchTheRealSizes) {
    auto device = EmbreeDevice::Create();
    ASSERT_TRUE(device.ok());
    auto source = StoreBrickSource::Open(path_, *device);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    for (uint32_t b = 0; b < (*source)->brick_count(); ++b) {
        auto h = (*source)->Acquire(b);
        ASSERT_TRUE(h.ok());
        EXPECT_EQ((*h)->memory_bytes(), (*source)->EstimatedResidentBytes(b)) << "brick " << b;
    }
}

TEST_F(PagerStoreTest, CorruptBrickMetWhilePagingNamesIt) {
    // Corrupt the brick with the most triangles (a ball in view): a byte in the middle of its mesh
    // section.
    uint32_t victim = 0;
    uint64_t offset = 0;
    {
        auto st = store::Store::Open(path_);
        ASSERT_TRUE(st.ok()) << st.status().ToString();
        for (const store::BrickInfo& b : (*st)->bricks()) {
            if (b.triangle_count > (*st)->bricks()[victim].triangle_count) victim = b.id;
        }
        const store::BrickInfo& b = (*st)->bricks()[victim];
        offset = b.mesh.offset + b.mesh.length / 2;
    }
    {
        std::fstream f(path_, std::ios::in | std::ios::out | std::ios::binary);
        f.seekg(std::streamoff(offset));
        char c = 0;
        f.read(&c, 1);
        c = char(c ^ 0x5a);
        f.seekp(std::streamoff(offset));
        f.write(&c, 1);
    }
    auto device = EmbreeDevice::Create();
    ASSERT_TRUE(device.ok());
    auto source = StoreBrickSource::Open(path_, *device);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    PagerOptions options = SmallBudget(**source);
    auto scene = BuildTestScene(std::move(*source), BallGridConfig("path"));
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    RunOptions run;
    run.paging = &options;
    const Status s = (*scene)->Run(run).status;
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find(fmt::format("brick {}", victim)), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("balls.nave"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace nave::render
