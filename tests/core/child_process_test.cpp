// RunInChildProcess: what the child sends arrives whole, and a child that aborts, is killed or
// exits with an error becomes an outcome the parent can report, never the parent's own death.

#include "src/core/child_process.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/sanitizers.h"
#include "src/core/memory.h"

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

// The child may use what the machine has free, no more: its address space is capped between the
// parent's current size and that plus the machine's physical memory.
TEST(ChildProcess, AddressSpaceIsCappedByTheAvailableMemory) {
    auto outcome = RunInChildProcess([](int fd) {
        rlimit as{};
        ::getrlimit(RLIMIT_AS, &as);
        const uint64_t limit = as.rlim_cur;
        return WriteAllToFd(fd, &limit, sizeof(limit)) ? 0 : 1;
    });
    ASSERT_TRUE(outcome.ok());
    ASSERT_EQ(outcome->output.size(), sizeof(uint64_t));
    uint64_t limit = 0;
    std::memcpy(&limit, outcome->output.data(), sizeof(limit));
    std::FILE* statm = std::fopen("/proc/self/statm", "r");
    ASSERT_NE(statm, nullptr);
    unsigned long long pages = 0;
    ASSERT_EQ(std::fscanf(statm, "%llu", &pages), 1);
    std::fclose(statm);
    const uint64_t parent_size = pages * uint64_t(::sysconf(_SC_PAGE_SIZE));
    EXPECT_NE(limit, uint64_t(RLIM_INFINITY));
    EXPECT_GT(limit, parent_size);
    EXPECT_LE(limit, parent_size + PhysicalMemoryBytes() + (uint64_t(64) << 20));  // + statm drift
#if !NAVE_TEST_UNDER_ASAN  // ASan's allocator aborts on such a size instead of failing it
    // And an allocation beyond it fails in the child instead of being granted.
    auto greedy = RunInChildProcess([](int) {
        try {
            std::vector<char> huge(size_t(ChildAddressSpaceLimitBytes()) + (size_t(1) << 30));
            return 1;
        } catch (const std::bad_alloc&) {
            return 3;
        }
    });
    ASSERT_TRUE(greedy.ok());
    EXPECT_TRUE(greedy->exited);
    EXPECT_EQ(greedy->exit_code, 3);
#endif
}

TEST(ChildProcess, WorksFromAProcessWithOtherThreadsRunning) {
    std::atomic<bool> stop{false};
    std::vector<std::thread> busy;
    busy.reserve(3);
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

// A child stuck in a loop is ended by its CPU-time limit; the parent learns it timed out.
TEST(ChildProcess, ASpinningChildIsStoppedAtItsTimeLimit) {
    const auto start = std::chrono::steady_clock::now();
    auto outcome = RunInChildProcess(
        [](int) {
            volatile uint64_t n = 0;
            for (;;) n = n + 1;
            return 0;
        },
        1.0);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
    EXPECT_TRUE(outcome->timed_out);
    EXPECT_FALSE(outcome->exited);
    // SIGXCPU after 1 s of CPU, or SIGKILL at the wall deadline (3 s) on a machine too busy to give
    // the child its second of CPU in time.
    EXPECT_TRUE(outcome->signal == SIGXCPU || outcome->signal == SIGKILL) << outcome->signal;
    EXPECT_GE(seconds, 0.9);
    EXPECT_LT(seconds, 20.0);
}

// A child blocked without using the CPU never reaches RLIMIT_CPU: the wall-clock deadline
// (twice the limit plus a second) ends it.
TEST(ChildProcess, ABlockedChildIsKilledAtTheWallDeadline) {
    const auto start = std::chrono::steady_clock::now();
    auto outcome = RunInChildProcess(
        [](int fd) {
            WriteAllToFd(fd, "before", 6);
            for (;;) ::pause();
            return 0;
        },
        0.5);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(outcome.ok()) << outcome.status().ToString();
    EXPECT_TRUE(outcome->timed_out);
    EXPECT_EQ(outcome->signal, SIGKILL);
    EXPECT_EQ(outcome->output, "before");
    EXPECT_GE(seconds, 1.9);
    EXPECT_LT(seconds, 20.0);
}

// Without a limit nothing is stopped.
TEST(ChildProcess, NoLimitMeansNoTimeout) {
    auto outcome = RunInChildProcess([](int) {
        ::usleep(300'000);
        return 4;
    });
    ASSERT_TRUE(outcome.ok());
    EXPECT_FALSE(outcome->timed_out);
    EXPECT_TRUE(outcome->exited);
    EXPECT_EQ(outcome->exit_code, 4);
}

}  // namespace
}  // namespace nave
