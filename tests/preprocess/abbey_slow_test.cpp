// The procedural abbey at full size (slow): detail scales the triangle count about linearly.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/abbey_source.h"
#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"
#include "preprocess/preprocess.h"
#include "test_util.h"

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

// The abbey at the size users meet (88 M triangles) stores in at most 2 bytes per input triangle
// at the default grid (0.1 mm error): flat stones store no normals, smooth piers, vaults and
// mouldings recompute theirs (docs/store-format.md, "Shading"). About 90 s on 2 cores.
TEST(AbbeySlow, DetailOneHundredTenStoresInTwoBytesPerTriangle) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("nave_abbey_size_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    PreprocessOptions o;
    o.generate = "abbey:detail=110";
    o.output = dir / "abbey110.nave";
    o.convert_textures = false;
    auto stats = RunPreprocess(o);
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();
    const double bytes_per_triangle = double(stats->output_bytes) / double(stats->source_triangles);
    std::printf("abbey detail 110: %llu triangles, %llu bytes, %.3f bytes per triangle\n",
                (unsigned long long)stats->source_triangles,
                (unsigned long long)stats->output_bytes, bytes_per_triangle);
    EXPECT_LE(bytes_per_triangle, 2.0)
        << "the detail-110 abbey took " << bytes_per_triangle << " bytes per input triangle";
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nave::preprocess
