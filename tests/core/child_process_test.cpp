// RunInChildProcess: what the child sends arrives whole, and a child that aborts, is killed or
// exits with an error becomes an outcome the parent can report, never the parent's own death.

#include "core/child_process.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace nave {
namespace {

TEST(ChildProcess, OutputArrivesWholeAndExitCodeIsKept) {
    // More than a pipe buffer (64 KiB), so the parent must read while the child writes.
    std::string sent(1 << 20, '\0');
    for (size_t i = 0; i < sent.size(); ++i) sent[i] = char(i * 131 % 251);
    auto outcome = RunInChildProcess(
        [&](int fd) { return WriteAllToFd(fd, sent.data(), sent.size()) ? 7 : 1; });
    ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
    EXPECT_TRUE(outcome->exited);
    EXPECT_EQ(outcome->exit_code, 7);
    EXPECT_EQ(outcome->signal, 0);
    EXPECT_EQ(outcome->output, sent);
}

TEST(ChildProcess, AbortIsReportedWithTheSignalAndTheLastWords) {
    auto outcome = RunInChildProcess([](int fd) {
        WriteAllToFd(fd, "partial", 7);
        std::fprintf(stderr, "ai_assert failure in somewhere.cpp(1): x != y\n");
        std::abort();
        return 0;
    });
    ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
    EXPECT_FALSE(outcome->exited);
    EXPECT_EQ(outcome->signal, SIGABRT);
    EXPECT_EQ(outcome->output, "partial");
    EXPECT_NE(outcome->stderr_tail.find("ai_assert failure in somewhere.cpp(1)"), std::string::npos)
        << outcome->stderr_tail;
    EXPECT_EQ(DescribeSignal(SIGABRT), "signal 6: Aborted");
}

TEST(ChildProcess, SegfaultAndExceptionDoNotReachTheParent) {
    auto segv = RunInChildProcess([](int) {
        std::raise(SIGSEGV);
        return 0;
    });
    ASSERT_TRUE(segv.ok());
    EXPECT_EQ(segv->signal, SIGSEGV);
    auto thrown = RunInChildProcess([](int) -> int { throw std::runtime_error("boom"); });
    ASSERT_TRUE(thrown.ok());
    EXPECT_TRUE(thrown->exited);
    EXPECT_EQ(thrown->exit_code, 125);
}

TEST(ChildProcess, StderrIsCutToItsTail) {
    auto outcome = RunInChildProcess([](int) {
        for (int i = 0; i < 5000; ++i) std::fprintf(stderr, "line %d\n", i);
        std::fprintf(stderr, "the end\n");
        std::fflush(stderr);
        return 0;
    });
    ASSERT_TRUE(outcome.ok());
    EXPECT_LE(outcome->stderr_tail.size(), 4096u);
    EXPECT_NE(outcome->stderr_tail.find("line 4999\nthe end\n"), std::string::npos);
    EXPECT_EQ(outcome->stderr_tail.find("line 0\n"), std::string::npos);
}

TEST(ChildProcess, WorksFromAProcessWithOtherThreadsRunning) {
    std::atomic<bool> stop{false};
    std::vector<std::thread> busy;
    for (int t = 0; t < 3; ++t) {
        busy.emplace_back([&] {
            while (!stop) {
                std::vector<int> v(1000);  // keep malloc's locks busy across the fork
                v[0] = 1;
            }
        });
    }
    for (int i = 0; i < 20; ++i) {
        auto outcome = RunInChildProcess([](int fd) {
            std::string s(100000, 'x');  // the child allocates too
            return WriteAllToFd(fd, s.data(), s.size()) ? 0 : 1;
        });
        ASSERT_TRUE(outcome.ok());
        EXPECT_TRUE(outcome->exited);
        EXPECT_EQ(outcome->exit_code, 0);
        EXPECT_EQ(outcome->output.size(), 100000u);
    }
    stop = true;
    for (auto& t : busy) t.join();
}

}  // namespace
}  // namespace nave
