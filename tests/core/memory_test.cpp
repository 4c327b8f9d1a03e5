#include "core/memory.h"

#include <gtest/gtest.h>

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
    EXPECT_GE(PeakRssBytes(), CurrentRssBytes());
    EXPECT_GT(PhysicalMemoryBytes(), PeakRssBytes());
    EXPECT_EQ(FormatBytes(1536), "1.5 KiB");
    EXPECT_EQ(FormatBytes(3ull << 30), "3.00 GiB");
}

}  // namespace
}  // namespace nave
