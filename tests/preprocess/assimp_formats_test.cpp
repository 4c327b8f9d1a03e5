// Every format the Assimp fuzz targets cover (tests/fuzz/assimp_formats.h) has a seed, and each
// seed reads through OpenModel, as `nave preprocess` reads it, as the unit square: two triangles of
// total area 1 spanning 1 by 1. A seed Assimp misreads would start the fuzzer from a file that
// tests nothing past the reader's first error.

#include "fuzz/assimp_formats.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>

#include "test_util.h"

namespace nave::preprocess {
namespace {

std::filesystem::path SeedOf(const std::string& extension) {
    // square.off is also an importer fixture, so it stays beside them.
    if (extension == "off") return testing::Fixture("square.off");
    return testing::Fixture("assimp/square." + extension);
}

TEST(AssimpFormats, EachSeedReadsAsTheUnitSquare) {
    for (const char* extension : fuzz::kAssimpFormats) {
        SCOPED_TRACE(extension);
        const std::filesystem::path seed = SeedOf(extension);
        ASSERT_TRUE(std::filesystem::exists(seed)) << seed << ": no seed for ." << extension;
        const std::vector<Triangle> triangles = testing::ReadModel(seed);
        ASSERT_EQ(triangles.size(), 2u);
        double area = 0;
        Bounds3d bounds;
        for (const Triangle& t : triangles) {
            area += testing::Area(t);
            for (const Vec3f& p : t.p) bounds.Extend(Vec3d(p));
        }
        EXPECT_NEAR(area, 1.0, 1e-5);
        // Some readers turn the model to Y-up, so the square may lie in any axis plane: its
        // bounds are 1 by 1 by 0 in some order.
        const Vec3d size = bounds.max - bounds.min;
        std::array<double, 3> sorted = {size.x, size.y, size.z};
        std::sort(sorted.begin(), sorted.end());
        EXPECT_NEAR(sorted[0], 0.0, 1e-5);
        EXPECT_NEAR(sorted[1], 1.0, 1e-5);
        EXPECT_NEAR(sorted[2], 1.0, 1e-5);
    }
}

}  // namespace
}  // namespace nave::preprocess
