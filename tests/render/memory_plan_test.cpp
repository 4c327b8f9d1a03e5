// How `nave render --memory` splits its budget: each share (queues, reserve, texture cache,
// checkpoint, load scratch, bricks), the wave size chosen when the bricks do not all fit, and the
// refusals at their boundary (one byte below the least budget that works), without rendering.

#include "src/render/stream/memory_plan.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "src/core/memory.h"
#include "src/render/bricks/procedural_scenes.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_memory.h"
#include "src/render/integrators/render_session.h"
#include "src/render/transport/path_guide.h"
#include "src/render/transport/photon_emitters.h"
#include "src/render/transport/visible_points.h"

namespace nave::render {
namespace {

constexpr uint64_t kMiB = uint64_t(1) << 20;

/// A 64x48 path render of a model of 4 bricks (20 MiB in all, the largest 6 MiB and 4 MiB) by a
/// process of 100 MiB, under 1 GiB.
RenderMemoryInputs SmallModel() {
    RenderMemoryInputs in;
    in.memory_bytes = 1024 * kMiB;
    in.memory_text = "1G";
    in.settings.mode = RenderSettings::Mode::kPath;
    in.settings.spp = 4;
    in.width = 64;
    in.height = 48;
    in.brick_count = 4;
    in.bricks.largest_brick = 3;
    in.bricks.largest_bytes = 6 * kMiB;
    in.bricks.second_brick = 1;
    in.bricks.second_bytes = 4 * kMiB;
    in.bricks.min_bytes = 10 * kMiB;
    in.bricks.total_bytes = 20 * kMiB;
    in.load_scratch_bytes = 1 * kMiB;
    in.process_bytes = 100 * kMiB;
    in.state = RenderStateMemory(in.settings, in.width, in.height, /*aov=*/false,
                                 /*checkpoints=*/false);
    return in;
}

uint64_t ReserveOf(const RenderMemoryInputs& in, const RenderSettings& settings,
                   uint64_t queue_memory_bytes) {
    return RenderReserveBytes(in, settings, queue_memory_bytes) + in.load_scratch_bytes;
}

TEST(RenderMemoryPlanTest, QueueMemoryIsAShareOfTheWholeBudget) {
    PagerOptions paging;
    paging.memory_bytes = 0;  // no --memory
    EXPECT_EQ(QueueMemoryBytes(paging), 32 * kMiB);
    paging.memory_bytes = 4096 * kMiB;
    EXPECT_EQ(QueueMemoryBytes(paging), 128 * kMiB);
    // The brick budget is not its base: one base, --memory.
    paging.brick_budget_bytes = 64 * kMiB;
    EXPECT_EQ(QueueMemoryBytes(paging), 128 * kMiB);
    paging.queue_memory_bytes = 5 * kMiB;  // the user's choice
    EXPECT_EQ(QueueMemoryBytes(paging), 5 * kMiB);
}

TEST(RenderMemoryPlanTest, RenderStateCountsTheFilmAndTheModesState) {
    RenderSettings path;
    path.mode = RenderSettings::Mode::kPath;
    path.path_guiding = true;
    RenderStateBytes state = RenderStateMemory(path, 64, 48, false, false);
    EXPECT_EQ(state.film, Film::MemoryBytes(64, 48));
    // Path mode's rounds overlap: the guide holds a second sum and distribution per cell.
    EXPECT_EQ(state.transport, PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGuideMaxCells,
                                                      GuideRounds::kDoublingPasses));
    EXPECT_GT(state.transport, PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGuideMaxCells));
    EXPECT_EQ(state.checkpoint, 0u);
    path.path_guiding = false;
    EXPECT_EQ(RenderStateMemory(path, 64, 48, false, false).transport, 0u);

    RenderSettings photon;
    photon.mode = RenderSettings::Mode::kPhoton;
    photon.photons_per_iteration = 100000;
    state = RenderStateMemory(photon, 64, 48, true, true);
    EXPECT_EQ(state.transport,
              VisiblePoints::MemoryBytes(64 * 48, false) + PhotonEmitters::LearningBytes(100000));
    EXPECT_EQ(state.checkpoint, CheckpointMemoryBytes(photon, 64, 48, true));
    // Caustic points (final gathering in a scene with smooth glass or metal): a second point per
    // pixel, not a second pixel state.
    const uint64_t caustic_extra =
        RenderStateMemory(photon, 64, 48, true, true, /*caustic_points=*/true).transport -
        state.transport;
    EXPECT_GT(caustic_extra, 0u);
    EXPECT_LT(caustic_extra, VisiblePoints::MemoryBytes(64 * 48, false));

    // The plan reserves them.
    RenderMemoryInputs in = SmallModel();
    const uint64_t without = RenderReserveBytes(in, in.settings, 0);
    in.state.transport += 7 * kMiB;
    in.state.film += 3 * kMiB;
    EXPECT_EQ(RenderReserveBytes(in, in.settings, 0), without + 10 * kMiB);
}

TEST(RenderMemoryPlanTest, BricksGetWhatTheReserveLeaves) {
    const RenderMemoryInputs in = SmallModel();
    StatusOr<RenderMemoryPlan> plan = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    // Queues: the automatic share of the whole budget.
    PagerOptions whole_budget;
    whole_budget.memory_bytes = in.memory_bytes;
    EXPECT_EQ(plan->queue_memory_bytes(), QueueMemoryBytes(whole_budget));
    EXPECT_EQ(plan->queue_memory_bytes(), in.memory_bytes / 32);
    EXPECT_EQ(plan->reserve_bytes(), ReserveOf(in, in.settings, plan->queue_memory_bytes()));
    EXPECT_EQ(plan->load_scratch_bytes(), in.load_scratch_bytes);
    EXPECT_EQ(plan->texture_cache_bytes(), 0u);
    EXPECT_EQ(plan->checkpoint_bytes(), 0u);
    EXPECT_EQ(plan->brick_budget_bytes(), in.memory_bytes - plan->reserve_bytes());
    // Every brick fits: the settings' wave size stays.
    EXPECT_FALSE(plan->chose_wave_paths());
    EXPECT_EQ(plan->wave_paths(), in.settings.wave_paths);
    EXPECT_EQ(plan->DescribeWaves(), "");
    // OpenImageIO is not loaded yet: writing the image adds it.
    EXPECT_EQ(plan->image_writer_bytes(),
              in.process_bytes + kImageWriterBytes + Film::MemoryBytes(in.width, in.height));

    PagerOptions pager;
    RenderSettings settings = in.settings;
    settings.wave_paths = 1234;
    plan->Apply(&pager, &settings);
    EXPECT_EQ(pager.brick_budget_bytes, plan->brick_budget_bytes());
    EXPECT_EQ(pager.queue_memory_bytes, plan->queue_memory_bytes());
    EXPECT_EQ(pager.memory_bytes, in.memory_bytes);
    EXPECT_EQ(settings.wave_paths, in.settings.wave_paths);

    const std::string text = plan->Describe();
    EXPECT_NE(text.find("--memory " + FormatBytes(in.memory_bytes)), std::string::npos) << text;
    EXPECT_NE(text.find(FormatBytes(plan->brick_budget_bytes()) + " for bricks"), std::string::npos)
        << text;
    EXPECT_NE(text.find("all 4 bricks at once, 20971520 bytes"), std::string::npos) << text;
    EXPECT_NE(text.find(std::to_string(plan->reserve_bytes()) + " bytes) reserved"),
              std::string::npos)
        << text;
    EXPECT_EQ(text.find("texture cache"), std::string::npos) << text;
}

TEST(RenderMemoryPlanTest, TextureCacheAndCheckpointAreReserved) {
    RenderMemoryInputs in = SmallModel();
    in.texture_cache_bytes = 12 * kMiB;
    in.image_library_loaded = true;
    in.state = RenderStateMemory(in.settings, in.width, in.height, /*aov=*/true,
                                 /*checkpoints=*/true);
    StatusOr<RenderMemoryPlan> plan = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    const uint64_t checkpoint = CheckpointMemoryBytes(in.settings, in.width, in.height, true);
    EXPECT_EQ(plan->checkpoint_bytes(), checkpoint);
    EXPECT_EQ(plan->texture_cache_bytes(), 12 * kMiB);
    EXPECT_EQ(plan->reserve_bytes(),
              ReserveOf(in, in.settings, plan->queue_memory_bytes()) + 12 * kMiB + checkpoint);
    EXPECT_EQ(plan->brick_budget_bytes(), in.memory_bytes - plan->reserve_bytes());
    // The texture cache loaded OpenImageIO already: the process's size counts it.
    EXPECT_EQ(plan->image_writer_bytes(),
              in.process_bytes + Film::MemoryBytes(in.width, in.height));
    EXPECT_NE(plan->Describe().find(", of which 12.0 MiB for the texture cache"), std::string::npos)
        << plan->Describe();
}

TEST(RenderMemoryPlanTest, QueueMemoryTheUserChoseIsKept) {
    RenderMemoryInputs in = SmallModel();
    in.pager.queue_memory_bytes = 5 * kMiB;
    StatusOr<RenderMemoryPlan> plan = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_EQ(plan->queue_memory_bytes(), 5 * kMiB);
    EXPECT_EQ(plan->reserve_bytes(), ReserveOf(in, in.settings, 5 * kMiB));
}

TEST(RenderMemoryPlanTest, OneWaveOfTheWholeImageWhenTheBricksDoNotAllFit) {
    RenderMemoryInputs in = SmallModel();
    in.bricks.total_bytes = 4096 * kMiB;  // more than the budget
    in.settings.wave_paths = 1024;
    StatusOr<RenderMemoryPlan> plan = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_TRUE(plan->chose_wave_paths());
    EXPECT_EQ(plan->wave_paths(), 64u * 48u * 4u);
    RenderSettings waves = in.settings;
    waves.wave_paths = 64 * 48 * 4;
    // The reserve is that of the waves chosen.
    EXPECT_EQ(plan->reserve_bytes(), ReserveOf(in, waves, plan->queue_memory_bytes()));
    EXPECT_EQ(plan->DescribeWaves(), fmt::format("waves of 12288 camera paths (--wave-paths); "
                                                 "their rays beyond {} of queues spill to disk",
                                                 FormatBytes(plan->queue_memory_bytes())));
    RenderSettings settings = in.settings;
    PagerOptions pager;
    plan->Apply(&pager, &settings);
    EXPECT_EQ(settings.wave_paths, 12288u);

    // Not when the user chose the waves, nor when the queues never spill.
    RenderMemoryInputs chosen = in;
    chosen.settings.wave_paths_chosen = true;
    plan = RenderMemoryPlan::Make(chosen);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_FALSE(plan->chose_wave_paths());
    EXPECT_EQ(plan->wave_paths(), 1024u);
    RenderMemoryInputs no_spill = in;
    no_spill.pager.queue_memory_bytes = 0;
    plan = RenderMemoryPlan::Make(no_spill);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_FALSE(plan->chose_wave_paths());
}

// With queues that never spill the reserve does not depend on the budget, so that the least budget
// one plan reports is exactly the boundary: accepted there, refused a byte below.
TEST(RenderMemoryPlanTest, TheLeastBudgetIsAcceptedAndOneByteLessRefused) {
    RenderMemoryInputs in = SmallModel();
    in.pager.queue_memory_bytes = 0;
    in.texture_cache_bytes = 12 * kMiB;
    in.image_library_loaded = true;
    StatusOr<RenderMemoryPlan> roomy = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(roomy.ok()) << roomy.status().ToString();
    const uint64_t minimum = roomy->minimum_bytes();
    // Here the bricks, not the image writer, set the minimum.
    EXPECT_EQ(minimum, roomy->reserve_bytes() + in.bricks.min_bytes);

    in.memory_bytes = minimum;
    StatusOr<RenderMemoryPlan> least = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(least.ok()) << least.status().ToString();
    EXPECT_EQ(least->brick_budget_bytes(), in.bricks.min_bytes);

    in.memory_bytes = minimum - 1;
    in.memory_text = std::to_string(minimum - 1);
    StatusOr<RenderMemoryPlan> refused = RenderMemoryPlan::Make(in);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
    const std::string& message = refused.status().message();
    EXPECT_EQ(message,
              fmt::format("--memory {0} ({0} bytes) is too small for this model: its largest "
                          "brick, brick 3, takes 6.0 MiB (6291456 bytes) when resident, and "
                          "prefetching needs room for the next-largest, brick 1 (4.0 MiB), the "
                          "reserve for the film, ray queues and process is {1} ({2} bytes), of "
                          "which 12.0 MiB for the texture cache, and writing the image afterwards "
                          "takes {3} ({4} bytes, OpenImageIO included): at least {5} ({6} bytes) "
                          "is needed (all 4 bricks resident at once take 20.0 MiB, 20971520 "
                          "bytes)",
                          minimum - 1, FormatBytes(least->reserve_bytes()), least->reserve_bytes(),
                          FormatBytes(least->image_writer_bytes()), least->image_writer_bytes(),
                          FormatBytes(minimum), minimum));
}

// A budget that holds the bricks while rendering but not OpenImageIO afterwards is refused too.
TEST(RenderMemoryPlanTest, TheImageWriterSetsTheMinimumWhenItNeedsMore) {
    RenderMemoryInputs in = SmallModel();
    in.pager.queue_memory_bytes = 0;
    in.width = 4096;  // a film of ~1.2 GiB
    in.height = 4096;
    in.settings.wave_paths = 1024;
    in.memory_bytes = uint64_t(64) << 30;
    StatusOr<RenderMemoryPlan> roomy = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(roomy.ok()) << roomy.status().ToString();
    EXPECT_EQ(roomy->minimum_bytes(), roomy->image_writer_bytes());
    EXPECT_GT(roomy->image_writer_bytes(), roomy->reserve_bytes() + in.bricks.min_bytes);

    in.memory_bytes = roomy->minimum_bytes();
    EXPECT_TRUE(RenderMemoryPlan::Make(in).ok());
    in.memory_bytes = roomy->minimum_bytes() - 1;
    in.memory_text = "tight";
    StatusOr<RenderMemoryPlan> refused = RenderMemoryPlan::Make(in);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
    EXPECT_NE(refused.status().message().find(fmt::format(
                  "writing the image afterwards takes {} ({} bytes",
                  FormatBytes(roomy->image_writer_bytes()), roomy->image_writer_bytes())),
              std::string::npos)
        << refused.status().message();
    EXPECT_EQ(refused.status().message().rfind("--memory tight (", 0), 0u)
        << refused.status().message();
}

// A model without bricks needs no brick budget: only the reserve and the image writer count.
TEST(RenderMemoryPlanTest, NoBricksNeedOnlyTheReserve) {
    RenderMemoryInputs in = SmallModel();
    in.brick_count = 0;
    in.bricks = BrickBudgetMinimum();
    in.pager.queue_memory_bytes = 0;
    StatusOr<RenderMemoryPlan> plan = RenderMemoryPlan::Make(in);
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_EQ(plan->minimum_bytes(), std::max(plan->reserve_bytes(), plan->image_writer_bytes()));
}

TEST(RenderMemoryPlanTest, TextureCacheCap) {
    TextureConfig textures;
    textures.cache_bytes = 256 * kMiB;
    textures.memory_share = 0.25;
    EXPECT_EQ(TextureCacheCapBytes(textures, std::nullopt), 256 * kMiB);
    EXPECT_EQ(TextureCacheCapBytes(textures, 400 * kMiB), 100 * kMiB);
    EXPECT_EQ(TextureCacheEnoughBytes(0), 4 * kMiB);
    EXPECT_EQ(TextureCacheEnoughBytes(10 * kMiB), 24 * kMiB);
}

TEST(RenderMemoryPlanTest, MeasureReadsTheBricksAndTheProcess) {
    auto device = EmbreeDevice::Create();
    ASSERT_TRUE(device.ok()) << device.status().ToString();
    auto source = OpenProceduralSource("clutter:bricks=2", *device);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    PagerOptions pager;
    pager.prefetch = false;
    const RenderMemoryInputs in = RenderMemoryInputs::Measure(**source, pager);
    EXPECT_EQ(in.brick_count, (*source)->brick_count());
    const BrickBudgetMinimum bricks = MinimumBrickBudget(**source, false);
    EXPECT_EQ(in.bricks.min_bytes, bricks.min_bytes);
    EXPECT_EQ(in.bricks.total_bytes, bricks.total_bytes);
    EXPECT_EQ(in.bricks.largest_brick, bricks.largest_brick);
    EXPECT_FALSE(in.pager.prefetch);
    uint64_t scratch = 0;
    for (uint32_t b = 0; b < in.brick_count; ++b)
        scratch = std::max(scratch, (*source)->LoadScratchBytes(b));
    EXPECT_EQ(in.load_scratch_bytes, scratch);
    EXPECT_GT(in.process_bytes, 0u);
}

}  // namespace
}  // namespace nave::render
