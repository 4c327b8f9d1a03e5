// `nave preprocess` run as a child process: peak memory stays under --memory for a stream several
// times larger, an interrupted run leaves no store and no temporary files, a killed run's leftovers
// are removed by the next run, and bad input exits with a message naming the file and line.

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "src/core/file.h"
#include "store/store_reader.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using ::testing::HasSubstr;

struct ChildResult {
    int exit_code = -1;  ///< when it exited
    int signal = 0;      ///< when a signal ended it
    uint64_t max_rss_bytes = 0;
    std::string err;
};

// Runs NAVE_BINARY with `args` in `dir`; sends `sig` after `signal_after_ms` if > 0.
ChildResult RunNave(const std::filesystem::path& dir, std::vector<std::string> args,
                    int signal_after_ms = 0, int sig = SIGINT) {
    std::filesystem::path err_path = dir / "stderr.txt";
    pid_t pid = fork();
    if (pid == 0) {
        if (chdir(dir.c_str()) != 0) _exit(127);
        int fd = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(fd, 2);
        std::vector<char*> argv;
        std::string bin = NAVE_BINARY;
        argv.push_back(bin.data());
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        execv(bin.c_str(), argv.data());
        _exit(127);
    }
    if (signal_after_ms > 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(signal_after_ms));
        kill(pid, sig);
    }
    int status = 0;
    struct rusage usage {};
    wait4(pid, &status, 0, &usage);
    ChildResult r;
    if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    r.max_rss_bytes = uint64_t(usage.ru_maxrss) * 1024;
    auto err = ReadFileToString(err_path);
    r.err = err.ok() ? *err : "";
    std::filesystem::remove(err_path);
    return r;
}

std::vector<std::string> Leftovers(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        std::string n = e.path().filename().string();
        if (n.find("tmp") != std::string::npos) names.push_back(n);
    }
    return names;
}

// The abbey at detail 3 is several million triangles: several times the 64 MiB budget as triangles
// in memory (104 bytes each). Its glass maps would need OpenImageIO (kTextureConversionBytes),
// which 64 MiB cannot hold: --no-textures (the next test checks the refusal without it).
TEST(PreprocessProcess, PeakMemoryStaysUnderTheBudget) {
    auto dir = testing::MakeTempDir("memory");
    const uint64_t budget = 64ull << 20;
    ChildResult r =
        RunNave(dir, {"preprocess", "--generate", "abbey:detail=3", "-o", "abbey.nave", "--memory",
                      "64M", "--brick-triangles", "20000", "--no-textures"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_LT(r.max_rss_bytes, budget)
        << "peak RSS " << r.max_rss_bytes << " over the budget " << budget;
    EXPECT_GT(r.max_rss_bytes, 0u);
    auto store = store::Store::Open(dir / "abbey.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_GT((*store)->header().source_triangle_count,
              4 * budget / 104);  // sizeof(Triangle) is 104 bytes
    EXPECT_THAT(Leftovers(dir), ::testing::IsEmpty());
    std::filesystem::remove_all(dir);
}

// With textures to convert, a budget that cannot hold OpenImageIO beside the work is refused,
// naming both ways out, and nothing is left behind; a budget that can hold it is kept (peak RSS
// under it).
TEST(PreprocessProcess, TextureConversionIsCountedInTheBudget) {
    auto dir = testing::MakeTempDir("texture_budget");
    ChildResult refused =
        RunNave(dir, {"preprocess", "--generate", "abbey:detail=0.25", "-o", "abbey.nave",
                      "--memory", "100M", "--brick-triangles", "20000"});
    EXPECT_NE(refused.exit_code, 0);
    EXPECT_THAT(refused.err, ::testing::HasSubstr("--no-textures"));
    EXPECT_THAT(refused.err, ::testing::HasSubstr("--memory"));
    EXPECT_FALSE(std::filesystem::exists(dir / "abbey.nave"));
    EXPECT_FALSE(std::filesystem::exists(dir / "abbey.nave.textures"));
    const uint64_t budget = 256ull << 20;
    ChildResult r = RunNave(dir, {"preprocess", "--generate", "abbey:detail=0.25", "-o",
                                  "abbey.nave", "--memory", "256M", "--brick-triangles", "20000"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_LT(r.max_rss_bytes, budget)
        << "peak RSS " << r.max_rss_bytes << " over the budget " << budget;
    EXPECT_TRUE(std::filesystem::exists(dir / "abbey.nave.textures"));
    std::filesystem::remove_all(dir);
}

TEST(PreprocessProcess, InterruptLeavesNoStoreAndNoTemporaries) {
    auto dir = testing::MakeTempDir("interrupt");
    for (int sig : {SIGINT, SIGTERM}) {
        // Detail 4 (~3.8 M triangles) is still being read or encoded when the signal comes, even on
        // an idle machine; detail 1 can finish first.
        ChildResult r = RunNave(dir,
                                {"preprocess", "--generate", "abbey:detail=4", "-o", "abbey.nave",
                                 "--brick-triangles", "50000"},
                                1500, sig);
        EXPECT_EQ(r.exit_code, 130) << "signal " << sig << ": " << r.err;
        EXPECT_THAT(r.err, HasSubstr("interrupted"));
        EXPECT_FALSE(std::filesystem::exists(dir / "abbey.nave"));
        EXPECT_THAT(Leftovers(dir), ::testing::IsEmpty());
    }
    std::filesystem::remove_all(dir);
}

TEST(PreprocessProcess, KilledRunLeavesNoValidStoreAndTheNextRunCleansUp) {
    auto dir = testing::MakeTempDir("kill");
    ChildResult r = RunNave(dir,
                            {"preprocess", "--generate", "abbey:detail=4", "-o", "abbey.nave",
                             "--brick-triangles", "50000"},
                            2500, SIGKILL);
    EXPECT_EQ(r.signal, SIGKILL);
    // Whatever it left cannot be opened as a store.
    EXPECT_FALSE(store::Store::Open(dir / "abbey.nave").ok());
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
        EXPECT_FALSE(store::Store::Open(e.path()).ok()) << e.path() << " opens as a valid store";
    }
    // A rerun (here on a small model) removes the dead run's temporaries.
    ChildResult ok =
        RunNave(dir, {"preprocess", std::string(NAVE_TEST_FIXTURES) + "/models/tetra_ascii.ply",
                      "-o", "abbey.nave", "--brick-triangles", "1000"});
    ASSERT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_THAT(Leftovers(dir), ::testing::IsEmpty());
    EXPECT_TRUE(store::Store::Open(dir / "abbey.nave").ok());
    std::filesystem::remove_all(dir);
}

TEST(PreprocessProcess, BadInputExitsWithFileAndLine) {
    auto dir = testing::MakeTempDir("badcli");
    ChildResult r = RunNave(
        dir,
        {"preprocess", std::string(NAVE_TEST_FIXTURES) + "/models/zero_index.obj", "-o", "x.nave"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_THAT(r.err, HasSubstr("zero_index.obj:4"));
    r = RunNave(dir, {"preprocess", std::string(NAVE_TEST_FIXTURES) + "/models/truncated.stl", "-o",
                      "x.nave"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_THAT(r.err, HasSubstr("234 bytes expected, found 224"));
    r = RunNave(dir, {"preprocess", "--generate", "abbey", "-o", "x.nave", "--memory", "10M"});
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_THAT(r.err, HasSubstr("--brick-triangles"));
    EXPECT_TRUE(std::filesystem::is_empty(dir)) << "failed runs must leave nothing";
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nave::preprocess
