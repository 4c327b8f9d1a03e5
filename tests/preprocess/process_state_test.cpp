// RunPreprocess as a library call leaves the process as it found it: no signal handler installed,
// no limit raised. Interruption comes from the caller, through PreprocessOptions::interrupt.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <atomic>

#include "preprocess/preprocess.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

struct ProcessState {
    struct sigaction sigint {};
    struct sigaction sigterm {};
    rlimit files{};
};

ProcessState Capture() {
    ProcessState s;
    EXPECT_EQ(sigaction(SIGINT, nullptr, &s.sigint), 0);
    EXPECT_EQ(sigaction(SIGTERM, nullptr, &s.sigterm), 0);
    EXPECT_EQ(getrlimit(RLIMIT_NOFILE, &s.files), 0);
    return s;
}

TEST(PreprocessLibrary, ChangesNoSignalDispositionAndNoLimit) {
    // A lower soft limit than the hard one, so that raising it would show.
    rlimit files{};
    ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &files), 0);
    const rlimit original = files;
    if (files.rlim_cur > 512 && files.rlim_cur != RLIM_INFINITY) {
        files.rlim_cur = 512;
        ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &files), 0);
    }
    const ProcessState before = Capture();

    auto dir = testing::MakeTempDir("state");
    PreprocessOptions o;
    o.inputs = {testing::Fixture("cylinder_on_box.obj")};
    o.output = dir.path() / "state.nave";
    auto stats = RunPreprocess(o);
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();

    const ProcessState after = Capture();
    EXPECT_EQ(after.sigint.sa_handler, before.sigint.sa_handler) << "SIGINT";
    EXPECT_EQ(after.sigterm.sa_handler, before.sigterm.sa_handler) << "SIGTERM";
    EXPECT_EQ(after.files.rlim_cur, before.files.rlim_cur) << "RLIMIT_NOFILE";
    setrlimit(RLIMIT_NOFILE, &original);
}

// A caller's signal handler stores the signal in the flag; the run stops with Cancelled and leaves
// nothing behind.
TEST(PreprocessLibrary, StopsWhenTheCallerAsks) {
    auto dir = testing::MakeTempDir("interrupt");
    std::atomic<int> interrupt{SIGTERM};
    PreprocessOptions o;
    o.inputs = {testing::Fixture("cylinder_on_box.obj")};
    o.output = dir.path() / "never.nave";
    o.interrupt = &interrupt;
    auto stats = RunPreprocess(o);
    ASSERT_FALSE(stats.ok());
    EXPECT_EQ(stats.status().code(), StatusCode::kCancelled);
    EXPECT_EQ(stats.status().message(),
              "interrupted by signal 15: output and temporary files removed");
    EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "an interrupted run leaves no file";
}

}  // namespace
}  // namespace nave::preprocess
