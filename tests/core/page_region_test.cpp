#include "src/core/page_region.h"

#include <gtest/gtest.h>

#include <cstring>

#include "src/core/memory.h"

namespace nave {
namespace {

TEST(PageRegion, MapsWholeZeroFilledPages) {
    auto empty = PageRegion::Map(0);
    ASSERT_TRUE(empty.ok());
    EXPECT_EQ(empty->data(), nullptr);
    EXPECT_EQ(empty->size(), 0u);

    auto r = PageRegion::Map(100);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_NE(r->data(), nullptr);
    EXPECT_EQ(r->size(), PageRegion::MappedBytes(100));
    EXPECT_GE(r->size(), 100u);
    EXPECT_EQ(r->size() % 4096, 0u);
    for (size_t i = 0; i < r->size(); ++i) ASSERT_EQ(r->data()[i], std::byte{0}) << i;
    std::memset(r->data(), 0xab, r->size());
    EXPECT_EQ(r->data()[r->size() - 1], std::byte{0xab});
}

TEST(PageRegion, LargeRegionsStartOnAHugePage) {
    auto r = PageRegion::Map((size_t(5) << 20) + 123);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(reinterpret_cast<uintptr_t>(r->data()) % (size_t(2) << 20), 0u);
    EXPECT_EQ(r->size(), PageRegion::MappedBytes((size_t(5) << 20) + 123));
    r->data()[r->size() - 1] = std::byte{1};  // the whole size is mapped
}

// AddressSanitizer keeps one shadow byte per 8 bytes the region's memset touched, resident after
// the region is unmapped: the sanitizer's memory, not the region's.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif
constexpr size_t SanitizerShadowBytes(size_t bytes) { return kAddressSanitizer ? bytes / 8 : 0; }

TEST(PageRegion, FreeingGivesThePagesBack) {
    // What the heap does not do for pieces freed between live ones: the process shrinks by the
    // region.
    constexpr size_t kBytes = size_t(64) << 20;
    const uint64_t before = CurrentRssBytes();
    ASSERT_GT(before, 0u) << "this system does not report the resident set size";
    {
        auto r = PageRegion::Map(kBytes);
        ASSERT_TRUE(r.ok()) << r.status().ToString();
        std::memset(r->data(), 1, r->size());
        EXPECT_GE(CurrentRssBytes(), before + kBytes * 9 / 10);
        PageRegion moved = std::move(r).value();
        EXPECT_EQ(r->data(), nullptr);  // NOLINT(bugprone-use-after-move): moved-from is empty
        EXPECT_EQ(moved.size(), PageRegion::MappedBytes(kBytes));
    }
    EXPECT_LE(CurrentRssBytes(), before + kBytes / 10 + SanitizerShadowBytes(kBytes));
}

TEST(PageRegion, AnImpossibleSizeIsAnErrorNamingIt) {
    auto r = PageRegion::Map(size_t(1) << 62);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted);
    EXPECT_NE(r.status().message().find(std::to_string(size_t(1) << 62)), std::string::npos)
        << r.status().message();
}

}  // namespace
}  // namespace nave
