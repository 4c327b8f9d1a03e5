// The procedural abbey: deterministic, the material names every render config maps, the size of the
// church, consistent normals, detail that scales the triangle count, and streaming in constant
// memory.

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

TEST(Abbey, PointedArchProfile) {
    // Crown at t = 0, springing at t = 1; the equilateral arch (rho = 2) rises sqrt(3) half-spans:
    // at t = 0.5 its height is sqrt(4 - 1.5^2) / sqrt(3) of the rise.
    EXPECT_DOUBLE_EQ(abbey::PointedArch(0, 2), 1.0);
    EXPECT_NEAR(abbey::PointedArch(1, 2), 0.0, 1e-12);
    EXPECT_NEAR(abbey::PointedArch(0.5, 2), std::sqrt(4 - 2.25) / std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(abbey::PointedArch(0.5, 1), std::sqrt(0.75), 1e-12);  // round arch: a circle
}

TEST(Abbey, DeterministicWithTheAgreedMaterialsAndSize) {
    auto a = MakeAbbeySource(0.25);
    auto b = MakeAbbeySource(0.25);
    Digest da = Consume(*a), db = Consume(*b);
    EXPECT_EQ(da.triangles, db.triangles);
    EXPECT_EQ(da.hash, db.hash) << "same detail must give the same triangles";
    std::vector<std::string> names;
    for (const auto& m : a->materials()) names.push_back(m.name);
    EXPECT_THAT(
        names, ::testing::ElementsAre("limestone", "limestone_dark", "floor_tile_light",
                                      "floor_tile_dark", "glass_clear", "glass_blue", "glass_red",
                                      "glass_yellow", "glass_green", "lead", "wood", "roof_slate"));
    for (size_t m = 0; m < da.per_material.size(); ++m)
        EXPECT_GT(da.per_material[m], 0u) << names[m];
    // About 100 m long east-west, apse to the east (+x), ridge near 39 m, floor at 0.
    EXPECT_GT(da.bounds.max.x - da.bounds.min.x, 95.0);
    EXPECT_LT(da.bounds.max.x - da.bounds.min.x, 110.0);
    EXPECT_GT(da.bounds.max.x, 95.0);
    EXPECT_NEAR(da.bounds.min.z, 0.0, 1e-3);
    EXPECT_GT(da.bounds.max.z, 38.0);
    EXPECT_LT(da.bounds.max.z, 45.0);
    EXPECT_EQ(a->units(), "m");
    EXPECT_GT(da.with_normals, 0u);
    EXPECT_EQ(da.bad_normals, 0u);
}

TEST(Abbey, PlanContainsNaveChoirChapelsNotOutside) {
    EXPECT_TRUE(abbey::InsidePlan(28, 0));      // nave
    EXPECT_TRUE(abbey::InsidePlan(28, 10));     // north aisle
    EXPECT_TRUE(abbey::InsidePlan(62, 24));     // north transept arm
    EXPECT_TRUE(abbey::InsidePlan(90, 0));      // apse
    EXPECT_TRUE(abbey::InsidePlan(83 + 9, 5));  // ambulatory
    EXPECT_TRUE(abbey::InsidePlan(98, 0));      // axial chapel
    EXPECT_FALSE(abbey::InsidePlan(28, 20));    // beside the aisle
    EXPECT_FALSE(abbey::InsidePlan(-5, 0));     // west of the facade
    EXPECT_FALSE(abbey::InsidePlan(75, 20));    // east of the transept, north of the choir aisle
}

TEST(Abbey, GeneratorSpecErrors) {
    EXPECT_TRUE(OpenGenerator("abbey").ok());
    EXPECT_TRUE(OpenGenerator("abbey:detail=0.5").ok());
    EXPECT_THAT(OpenGenerator("castle").status().message(), ::testing::HasSubstr("unknown"));
    EXPECT_THAT(OpenGenerator("abbey:detail=-1").status().message(),
                ::testing::HasSubstr("must be a number"));
    EXPECT_THAT(OpenGenerator("abbey:size=3").status().message(),
                ::testing::HasSubstr("expected detail=D"));
}

}  // namespace
}  // namespace nave::preprocess
