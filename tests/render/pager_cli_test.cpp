// The pager as users reach it: `nave render --memory` on procedural models and stores, its refusals
// and its report.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/file_size_limit.h"
#include "common/run_nave.h"
#include "common/sanitizers.h"
#include "pager_test_scene.h"
#include "render_test_util.h"
#include "src/core/memory.h"
#include "src/render/stream/memory_plan.h"

namespace nave::render {
namespace {
TEST(PagerCliTest, TooSmallMemoryIsRefusedNamingTheBrickAndTheMinimum) {
    const std::string config = std::string(NAVE_TEST_FIXTURES) + "/../../configs/test_clutter.toml";
    const auto out = std::filesystem::temp_directory_path() /
                     ("nave_memory_" + std::to_string(getpid()) + ".exr");
    const test::CommandResult r =
        test::RunNave("render --procedural clutter:bricks=4 --config " + config +
                      " --resolution 16x12 --spp 1 --memory 1M -o " + out.string());
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("--memory 1M"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("largest brick, brick "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("at least"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(PagerCliTest, AFullDiskWhileSpillingNamesTheSpillDirectoryAndWritesNoImage) {
    const std::string config = std::string(NAVE_TEST_FIXTURES) + "/../../configs/test_clutter.toml";
    const auto dir =
        std::filesystem::temp_directory_path() / ("nave_spill_full_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    const auto out = dir / "clutter.exr";
    // Queues over 4 KiB spill; a file size limit of 8 KiB (inherited by nave) fails the spill as a
    // full disk would.
    test::CommandResult r;
    {
        test::ScopedFileSizeLimit limit(8 << 10);
        ASSERT_TRUE(limit.ok());
        r = test::RunNave("render --procedural clutter:bricks=4 --config " + config +
                          " --resolution 64x48 --spp 2 --memory 256M --pager queue_memory=4K "
                          "--temp-dir " +
                          dir.string() + " -o " + out.string());
    }
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("ray queues to " + dir.string()), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--temp-dir"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_TRUE(std::filesystem::is_empty(dir));  // no partial image, no spill file left
    std::filesystem::remove_all(dir);
}

TEST(PagerCliTest, MemoryBudgetRendersAndReportsPaging) {
    const std::string config = std::string(NAVE_TEST_FIXTURES) + "/../../configs/test_clutter.toml";
    const auto out = std::filesystem::temp_directory_path() /
                     ("nave_memory_ok_" + std::to_string(getpid()) + ".exr");
    const test::CommandResult r = test::RunNave(
        "render --procedural clutter:bricks=4 --config " + config +
        " --resolution 16x12 --spp 1 --memory 256M --pager prefetch=off -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("(--memory 256M)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("evictions"), std::string::npos) << r.output;
    const test::CommandResult bad =
        test::RunNave("render --procedural clutter:bricks=4 --config " + config +
                      " --memory 256M --pager speed=11 -o " + out.string());
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_NE(bad.output.find("speed"), std::string::npos) << bad.output;
    std::filesystem::remove(out);
    std::filesystem::remove(std::filesystem::path(out).replace_extension(".png"));
}

// Paging thousands of bricks in and out keeps the process within its budget only with jemalloc:
// glibc's heap grew to twice what it held (docs/pager.md, "Memory").
TEST(PagerCliTest, NaveAllocatesWithJemalloc) {
    const test::CommandResult r = test::RunNave("version");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("allocator: jemalloc 5."), std::string::npos) << r.output;
}

// The whole process, not only its bricks, stays within --memory + 64 MiB (VmHWM as nave reports it
// at exit, image writing included) at the smallest budget nave accepts, halfway to in-core, and
// with room for every brick: a store of 6 x 6 dense balls in 72 bricks.
TEST(PagerCliTest, WholeProcessPeakStaysWithinTheBudget) {
#if NAVE_TEST_UNDER_ASAN
    GTEST_SKIP() << "AddressSanitizer's shadow memory and quarantine are not in nave's budget";
#endif
    const auto dir =
        std::filesystem::temp_directory_path() / fmt::format("nave_pager_memory_{}", getpid());
    std::filesystem::create_directories(dir);
    store::BrickMesh mesh;
    AppendQuad(&mesh, {0, 0, 0}, {6, 0, 0}, {0, 6, 0}, 12, 0);
    for (int i = 0; i < 6; ++i) {
        for (int j = 0; j < 6; ++j) {
            AppendSphere(&mesh, {-5 + 2.f * float(i), -5 + 2.f * float(j), 0.7f}, 0.6f, 48, 96, 1);
        }
    }
    const auto store_path = dir / "dense.nave";
    ASSERT_TRUE(testing::WriteGridBricksStore(store_path, mesh, kNames, {6, 6, 2}).ok());
    const auto config = dir / "dense.toml";
    {
        std::ofstream f(config);
        f << fmt::format(fmt::runtime(kBallGrid), "path");
    }
    const std::string render = "render " + store_path.string() + " --config " + config.string() +
                               " --resolution 64x48 --spp 2 -o " + (dir / "out.exr").string();
    auto bytes_after = [](const std::string& text, const std::string& marker) -> uint64_t {
        const size_t at = text.find(marker);
        if (at == std::string::npos) return 0;
        const size_t open = text.find('(', at + marker.size());
        return open == std::string::npos ? 0 : std::stoull(text.substr(open + 1));
    };
    const test::CommandResult refused = test::RunNave(render + " --memory 1M");
    ASSERT_NE(refused.exit_code, 0);
    // "... at least 205.3 MiB (215233376 bytes) is needed (all 132 bricks resident at once take
    // 190.8 MiB, 200044776 bytes)"
    const uint64_t minimum = bytes_after(refused.output, "at least");
    const size_t take = refused.output.find("at once take");
    const size_t comma = refused.output.find(", ", take);
    const uint64_t all_bricks = take == std::string::npos || comma == std::string::npos
                                    ? 0
                                    : std::stoull(refused.output.substr(comma + 2));
    ASSERT_GT(minimum, 0u) << refused.output;
    ASSERT_GT(all_bricks, 0u) << refused.output;
    // The minimum counts the process's size when the render is planned, which differs by a few
    // pages from one run to the next: start 4 MiB above it.
    const uint64_t smallest = minimum + (uint64_t(4) << 20);
    for (const uint64_t budget : {smallest, smallest + all_bricks / 2, smallest + all_bricks}) {
        const test::CommandResult r = test::RunNave(render + " --memory " + std::to_string(budget));
        ASSERT_EQ(r.exit_code, 0) << r.output;
        const uint64_t peak = bytes_after(r.output, "peak memory");
        ASSERT_GT(peak, 0u) << r.output;
        EXPECT_LE(peak, budget + (uint64_t(64) << 20))
            << "--memory " << budget << " (" << FormatBytes(budget) << "): the process peaked at "
            << FormatBytes(peak) << "\n"
            << r.output;
    }
    std::filesystem::remove_all(dir);
}

TEST(PagerWaves, UnderPagingAPathRenderIsOneWaveUnlessTheUserChose) {
    RenderSettings s;
    s.mode = RenderSettings::Mode::kPath;
    s.spp = 4;
    // 640x427 at 4 spp: one wave of every path.
    EXPECT_EQ(WavePathsUnderPaging(s, 640, 427), 640u * 427u * 4u);
    // Never below the default wave, never above the cap.
    EXPECT_EQ(WavePathsUnderPaging(s, 16, 16), s.wave_paths);
    s.spp = 1024;
    EXPECT_EQ(WavePathsUnderPaging(s, 1920, 1080), kMaxPagedWavePaths);
    // The user's choice (config or --wave-paths) stands, and photon mode keeps its waves.
    s.wave_paths_chosen = true;
    s.wave_paths = 5000;
    EXPECT_EQ(WavePathsUnderPaging(s, 640, 427), 5000u);
    s.wave_paths_chosen = false;
    s.mode = RenderSettings::Mode::kPhoton;
    EXPECT_EQ(WavePathsUnderPaging(s, 640, 427), 5000u);
}

}  // namespace
}  // namespace nave::render
