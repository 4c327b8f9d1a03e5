// The procedural abbey at full size (slow): detail scales the triangle count about linearly.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/abbey_source.h"
#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"

namespace nave::preprocess {
namespace {

struct Digest {
    uint64_t triangles = 0, with_normals = 0, bad_normals = 0;
    uint64_t hash = 1469598103934665603ull;
    Bounds3d bounds;
    std::vector<uint64_t> per_material;
};

Digest Consume(TriangleSource& source) {
    Digest d;
    d.per_material.assign(source.materials().size(), 0);
    std::vector<Triangle> batch;
    while (true) {
        auto more = source.Next(batch, 5000);
        EXPECT_TRUE(more.ok());
        if (!more.ok() || !*more) break;
        for (const Triangle& t : batch) {
            ++d.triangles;
            ++d.per_material.at(t.material);
            for (const Vec3f& p : t.p) {
                d.bounds.Extend(Vec3d(p));
                uint32_t bits[3];
                std::memcpy(bits, &p, 12);
                for (uint32_t b : bits) d.hash = (d.hash ^ b) * 1099511628211ull;
            }
            if (t.has_normals) {
                ++d.with_normals;
                Vec3f g = Cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
                for (const Vec3f& n : t.n) {
                    // A shading normal on the back of its triangle would be a winding error.
                    if (!(Dot(n, g) > 0) || std::abs(Length(n) - 1) > 1e-3f) ++d.bad_normals;
                }
            }
        }
    }
    return d;
}

// Triangles grow about linearly with detail (docs/abbey.md has the table).
TEST(AbbeySlow, DetailScalesTriangles) {
    auto small = MakeAbbeySource(1.0);
    Digest d1 = Consume(*small);
    EXPECT_GT(d1.triangles, 800'000u);
    EXPECT_LT(d1.triangles, 2'000'000u);
    auto coarse = MakeAbbeySource(0.25);
    Digest d025 = Consume(*coarse);
    EXPECT_LT(d025.triangles, d1.triangles / 2);
    std::printf("abbey triangles: detail 0.25 -> %llu, detail 1 -> %llu\n",
                (unsigned long long)d025.triangles, (unsigned long long)d1.triangles);
}

TEST(AbbeySlow, DetailFourHasMoreThanTwiceDetailOne) {
    Digest d1 = Consume(*MakeAbbeySource(1.0));
    Digest d4 = Consume(*MakeAbbeySource(4.0));
    double ratio = double(d4.triangles) / double(d1.triangles);
    std::printf("abbey triangles: detail 4 -> %llu (%.2f x detail 1)\n",
                (unsigned long long)d4.triangles, ratio);
    EXPECT_GT(ratio, 2.0);
    EXPECT_LT(ratio, 5.0);
}

}  // namespace
}  // namespace nave::preprocess
