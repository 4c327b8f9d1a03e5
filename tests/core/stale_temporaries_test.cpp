#include "src/core/stale_temporaries.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

namespace nave {
namespace {

/// The id of a process that has surely ended: a child that exited and was reaped.
long DeadPid() {
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    int status = 0;
    ::waitpid(child, &status, 0);
    return long(child);
}

TEST(StaleTemporariesTest, OwnerIsReadOnlyFromNaveNames) {
    EXPECT_EQ(TemporaryOwner("a.exr.tmp-123-4", "a.exr.tmp-", ""), 123);
    EXPECT_EQ(TemporaryOwner("a.tmp-123-4.exr", "a.tmp-", ".exr"), 123);
    EXPECT_EQ(TemporaryOwner("a.tmp-123-4.png", "a.tmp-", ".exr"), -1);
    EXPECT_EQ(TemporaryOwner("a.tmp-123-4x.exr", "a.tmp-", ".exr"), -1);
    EXPECT_EQ(TemporaryOwner("a.tmp-123.exr", "a.tmp-", ".exr"), -1);
    EXPECT_EQ(TemporaryOwner("a.tmp--5-1", "a.tmp-", ""), -1);
    EXPECT_EQ(TemporaryOwner("a.tmp-0-1", "a.tmp-", ""), -1);
    EXPECT_EQ(TemporaryOwner("a.tmp-5--1", "a.tmp-", ""), -1);
    EXPECT_EQ(TemporaryOwner("b.tmp-5-1", "a.tmp-", ""), -1);
    EXPECT_EQ(TemporaryOwner(".nave-tmp-77-0", ".nave-tmp-", ""), 77);
}

TEST(StaleTemporariesTest, RemovesTheDeadsOnlyDirectoriesIncluded) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("nave_stale_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string dead = std::to_string(DeadPid());
    const std::string alive = std::to_string(::getppid());
    const std::string self = std::to_string(::getpid());
    for (const std::string& name :
         {"out.nave.tmp-" + dead + "-0", "out.nave.tmp-" + alive + "-0",
          "out.nave.tmp-" + self + "-0", std::string("out.nave"), "x.tmp-" + dead + "-0"})
        std::ofstream(dir / name) << "x";
    std::filesystem::create_directories(dir / (".nave-tmp-" + dead + "-2") / "inner");

    auto removed = RemoveStaleTemporaries(dir, "out.nave.tmp-");
    ASSERT_EQ(removed.size(), 1u);
    EXPECT_EQ(removed[0], dir / ("out.nave.tmp-" + dead + "-0"));
    removed = RemoveStaleTemporaries(dir, ".nave-tmp-");
    ASSERT_EQ(removed.size(), 1u);
    EXPECT_FALSE(std::filesystem::exists(dir / (".nave-tmp-" + dead + "-2")));
    for (const std::string& kept : {"out.nave.tmp-" + alive + "-0", "out.nave.tmp-" + self + "-0",
                                    std::string("out.nave"), "x.tmp-" + dead + "-0"})
        EXPECT_TRUE(std::filesystem::exists(dir / kept)) << kept;
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nave
