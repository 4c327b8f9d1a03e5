// BrickBuilder + the store's encoder: triangles without normals in a brick that has normals come
// out flat (no stored normals, corners shared) however small they are next to the grid step.

#include "preprocess/partition/brick_builder.h"

#include <gtest/gtest.h>

#include <random>

#include "store/brick_codec.h"

namespace nave::preprocess {
namespace {

TEST(BrickBuilder, SmallFacesWithoutNormalsStayFlatBesideSmoothOnes) {
    const store::GlobalGrid grid{{-1.0, -1.0, -1.0}, 1e-4};
    std::vector<Triangle> triangles;
    // A tooled stone face: 20 x 20 quads of 2 mm (20 grid steps) whose inner corners stand out by
    // up to 0.5 mm, without normals, as the abbey's generator emits its stones.
    const int n = 20;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> relief(-5e-4f, 5e-4f);
    std::vector<float> z((n + 1) * (n + 1));
    for (int k = 0; k <= n; ++k) {
        for (int i = 0; i <= n; ++i) {
            z[k * (n + 1) + i] = (i > 0 && i < n && k > 0 && k < n) ? relief(rng) : 0.f;
        }
    }
    auto corner = [&](int i, int k) { return Vec3f(0.002f * i, 0.002f * k, z[k * (n + 1) + i]); };
    for (int k = 0; k < n; ++k) {
        for (int i = 0; i < n; ++i) {
            Triangle a, b;
            a.p = {corner(i, k), corner(i + 1, k), corner(i + 1, k + 1)};
            b.p = {corner(i, k), corner(i + 1, k + 1), corner(i, k + 1)};
            triangles.push_back(a);
            triangles.push_back(b);
        }
    }
    // One smooth triangle elsewhere gives the brick normals.
    Triangle smooth;
    smooth.p = {Vec3f(0.5f, 0, 0), Vec3f(0.6f, 0, 0), Vec3f(0.5f, 0.1f, 0.01f)};
    smooth.n = {Vec3f(0, 0, 1), Normalize(Vec3f(0.1f, 0, 1)), Normalize(Vec3f(0, 0.2f, 1))};
    smooth.has_normals = true;
    triangles.push_back(smooth);

    BrickBuilder builder;
    const BuiltBrick& built = builder.Build(triangles, grid);
    ASSERT_TRUE(built.mesh.HasNormals());
    auto encoded = store::codec::EncodeMeshSection(built.mesh, grid, store::EncodeOptions());
    ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
    auto decoded = store::codec::DecodeMeshSection(encoded->bytes, grid, 1, "test brick");
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    ASSERT_EQ(decoded->TriangleCount(), triangles.size());
    size_t flat = 0;
    for (size_t t = 0; t < decoded->TriangleCount(); ++t) {
        flat += Length(decoded->normals[decoded->indices[3 * t]]) == 0.f;
    }
    EXPECT_EQ(flat, size_t(2 * n * n)) << "faces without normals must come out flat";
    // The face's (n + 1)^2 corners shared, plus the smooth triangle's three.
    EXPECT_EQ(decoded->VertexCount(), size_t((n + 1) * (n + 1) + 3));
}

}  // namespace
}  // namespace nave::preprocess
