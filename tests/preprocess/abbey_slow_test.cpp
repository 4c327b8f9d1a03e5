// The procedural abbey at full size (slow): detail scales the triangle count about linearly.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/abbey_source.h"
#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"

namespace nave::preprocess {
namespace {

using testing::AbbeyDigest;
using testing::DigestOf;

// Triangles grow about linearly with detail (docs/abbey.md has the table).
TEST(AbbeySlow, DetailScalesTriangles) {
    auto small = MakeAbbeySource(1.0);
    AbbeyDigest d1 = DigestOf(*small);
    EXPECT_GT(d1.triangles, 800'000u);
    EXPECT_LT(d1.triangles, 2'000'000u);
    auto coarse = MakeAbbeySource(0.25);
    AbbeyDigest d025 = DigestOf(*coarse);
    EXPECT_LT(d025.triangles, d1.triangles / 2);
    std::printf("abbey triangles: detail 0.25 -> %llu, detail 1 -> %llu\n",
                (unsigned long long)d025.triangles, (unsigned long long)d1.triangles);
}

TEST(AbbeySlow, DetailFourHasMoreThanTwiceDetailOne) {
    AbbeyDigest d1 = DigestOf(*MakeAbbeySource(1.0));
    AbbeyDigest d4 = DigestOf(*MakeAbbeySource(4.0));
    double ratio = double(d4.triangles) / double(d1.triangles);
    std::printf("abbey triangles: detail 4 -> %llu (%.2f x detail 1)\n",
                (unsigned long long)d4.triangles, ratio);
    EXPECT_GT(ratio, 2.0);
    EXPECT_LT(ratio, 5.0);
}

}  // namespace
}  // namespace nave::preprocess
