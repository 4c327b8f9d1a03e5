#include "src/render/bricks/resident_mesh.h"

#include <gtest/gtest.h>

#include <cstddef>

#include "expect_same_mesh.h"

namespace nave::render {
namespace {

store::BrickMesh Strip(size_t triangles, bool normals, bool uvs) {
    store::BrickMesh m;
    for (size_t v = 0; v < triangles + 2; ++v) {
        const size_t column = v / 2;
        m.positions.push_back(Vec3f(float(column), float(v % 2), 0.25f * float(v)));
        if (normals) m.normals.push_back(Vec3f(0, 0, 1));
        if (uvs) m.uvs.push_back({float(v) * 0.5f, float(v % 2)});
    }
    for (uint32_t t = 0; t < triangles; ++t) {
        m.indices.insert(m.indices.end(), {t, t + 1, t + 2});
        m.material_ids.push_back(t % 3);
    }
    return m;
}

TEST(ResidentMesh, CopiesEveryArrayIntoOneRegionOfTheSizeItAnnounces) {
    for (bool normals : {false, true}) {
        for (bool uvs : {false, true}) {
            const store::BrickMesh m = Strip(1000, normals, uvs);
            auto r = ResidentMesh::CopyOf(m);
            ASSERT_TRUE(r.ok()) << r.status().ToString();
            const ResidentMesh& mesh = *r;
            testing::ExpectSameMesh(mesh, m);
            EXPECT_EQ(mesh.TriangleCount(), 1000u);
            EXPECT_EQ(mesh.HasNormals(), normals);
            EXPECT_EQ(mesh.HasUvs(), uvs);
            EXPECT_EQ(mesh.MemoryBytes(), ResidentMesh::MemoryBytesFor({1002, 1000, normals, uvs}));

            // The arrays lie one after the other, cache-line aligned, inside the region; the
            // positions leave one vertex of room before the next array (Embree reads 16 bytes at
            // the last one).
            const auto* begin = reinterpret_cast<const std::byte*>(mesh.positions.data());
            const std::byte* end = begin + mesh.MemoryBytes();
            const std::byte* at = reinterpret_cast<const std::byte*>(mesh.positions.data() + 1003);
            auto check = [&](const void* data, size_t bytes) {
                if (bytes == 0) return;
                const auto* p = static_cast<const std::byte*>(data);
                EXPECT_EQ(reinterpret_cast<uintptr_t>(p) % 64, 0u);
                EXPECT_GE(p, at);
                at = p + bytes;
                EXPECT_LE(at, end);
            };
            check(mesh.normals.data(), mesh.normals.size_bytes());
            check(mesh.uvs.data(), mesh.uvs.size_bytes());
            check(mesh.indices.data(), mesh.indices.size_bytes());
            check(mesh.material_ids.data(), mesh.material_ids.size_bytes());
        }
    }
}

TEST(ResidentMesh, AnEmptyMeshHoldsRoomForTheSpareVertexOnly) {
    auto r = ResidentMesh::CopyOf(store::BrickMesh());
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->TriangleCount(), 0u);
    EXPECT_EQ(r->VertexCount(), 0u);
    EXPECT_EQ(r->MemoryBytes(), ResidentMesh::MemoryBytesFor({}));
    EXPECT_GT(r->MemoryBytes(), 0u);
}

}  // namespace
}  // namespace nave::render
