#include "src/core/memory.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace nave {
namespace {

TEST(ParseByteSizeTest, AcceptsUnitsAsPowersOf1024) {
    EXPECT_EQ(ParseByteSize("1048576").value(), 1048576u);
    EXPECT_EQ(ParseByteSize("64K").value(), 64u * 1024);
    EXPECT_EQ(ParseByteSize("512M").value(), 512ull << 20);
    EXPECT_EQ(ParseByteSize("1.5G").value(), 3ull << 29);
    EXPECT_EQ(ParseByteSize("2GiB").value(), 2ull << 30);
    EXPECT_EQ(ParseByteSize("300mb").value(), 300ull << 20);
}

TEST(ParseByteSizeTest, RejectsGarbageWithTheText) {
    for (const char* bad : {"", "G", "12X", "-5M", "1.2.3G", "99999999999999T"}) {
        auto r = ParseByteSize(bad);
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_NE(r.status().message().find("is not a size"), std::string::npos);
    }
}

TEST(MemoryTest, ProcessAndMachineSizesAreMeasured) {
    EXPECT_GT(PeakRssBytes(), 0u);
    // The current size first: the peak read after it has seen it, whatever grows in between.
    const uint64_t current = CurrentRssBytes();
    EXPECT_GE(PeakRssBytes(), current);
    EXPECT_GT(PhysicalMemoryBytes(), PeakRssBytes());
    EXPECT_EQ(FormatBytes(1536), "1.5 KiB");
    EXPECT_EQ(FormatBytes(3ull << 30), "3.00 GiB");
}

TEST(MemoryTest, CurrentRssAgreesWithTheKernelsStatus) {
    // CurrentRssBytes reads /proc/self/statm; /proc/self/status says the same in KiB.
    std::ifstream status("/proc/self/status");
    std::string line;
    uint64_t vm_rss = 0;
    while (std::getline(status, line)) {
        if (line.rfind("VmRSS:", 0) == 0) vm_rss = std::stoull(line.substr(6)) * 1024;
    }
    ASSERT_GT(vm_rss, 0u);
    const uint64_t rss = CurrentRssBytes();
    EXPECT_GT(rss, vm_rss / 2);
    EXPECT_LT(rss, vm_rss * 2);
}

TEST(ResidentSizeGuardTest, GivesPagesBackOnlyWhenTheNextAllocationWouldPassTheLimitOrTheSlack) {
    // Without a limit: the first check gives pages back and measures the process; then only what
    // passes half of that plus 128 MiB does.
    ResidentSizeGuard none(0);
    EXPECT_TRUE(none.MakeRoom(0));
    EXPECT_FALSE(none.MakeRoom(uint64_t(1) << 20));
    EXPECT_TRUE(none.MakeRoom(uint64_t(1) << 40));
    EXPECT_EQ(none.returns(), 2u);

    const uint64_t rss = CurrentRssBytes();
    ResidentSizeGuard roomy(rss + (uint64_t(1) << 30));
    EXPECT_FALSE(roomy.MakeRoom(uint64_t(1) << 20));  // 1 MiB more fits under 1 GiB of headroom
    EXPECT_EQ(roomy.returns(), 0u);
    EXPECT_TRUE(roomy.MakeRoom(uint64_t(2) << 30));  // 2 GiB more does not
    EXPECT_EQ(roomy.returns(), 1u);

    ResidentSizeGuard tight(rss / 2);  // already over
    EXPECT_TRUE(tight.MakeRoom(0));
    EXPECT_TRUE(tight.MakeRoom(0));
    EXPECT_EQ(tight.returns(), 2u);
}

}  // namespace
}  // namespace nave
