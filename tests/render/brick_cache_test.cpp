#include "src/render/bricks/brick_cache.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/file_size_limit.h"
#include "expect_same_mesh.h"

namespace nave::render {
namespace {

store::BrickMesh TwoTriangles(bool normals, bool uvs) {
    store::BrickMesh m;
    m.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 1, 0), Vec3f(0, 1, 0.5f)};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material_ids = {3, 7};
    if (normals) m.normals = {Vec3f(0, 0, 1), Vec3f(0, 0, 0), Vec3f(0, 0.6f, 0.8f), Vec3f(1, 0, 0)};
    if (uvs) m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0.25f, 0.75f}};
    return m;
}

std::unique_ptr<store::SpillFile> NewSpillFile() {
    auto file = store::SpillFile::Create(std::filesystem::temp_directory_path(), "the brick cache");
    EXPECT_TRUE(file.ok()) << file.status().ToString();
    return std::move(file).value();
}

using testing::ExpectSameMesh;

TEST(BrickCache, ReadsBackWhatItWasGivenWithAndWithoutNormalsAndUvs) {
    BrickCache cache(NewSpillFile(), 4, uint64_t(1) << 30);
    for (uint32_t b = 0; b < 4; ++b) {
        EXPECT_FALSE(cache.Has(b));
        cache.Put(b, TwoTriangles(b & 1, b & 2));
    }
    for (uint32_t b = 0; b < 4; ++b) {
        ASSERT_TRUE(cache.Has(b));
        auto mesh = cache.Get(b);
        ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
        ExpectSameMesh(*mesh, TwoTriangles(b & 1, b & 2));
        const store::BrickMesh m = TwoTriangles(b & 1, b & 2);
        EXPECT_EQ(mesh->MemoryBytes(),
                  ResidentMesh::MemoryBytesFor(
                      {m.VertexCount(), m.TriangleCount(), m.HasNormals(), m.HasUvs()}));
    }
    const BrickCacheStats s = cache.stats();
    EXPECT_EQ(s.bricks_written, 4u);
    EXPECT_EQ(s.reads, 4u);
    EXPECT_GT(s.disk_bytes, 0u);
    EXPECT_LE(s.disk_bytes, s.mesh_bytes);
}

TEST(BrickCache, AMeshOverTheLimitIsNotCached) {
    BrickCache cache(NewSpillFile(), 2, 10);  // 10 bytes: no mesh fits
    cache.Put(0, TwoTriangles(true, true));
    EXPECT_FALSE(cache.Has(0));
    EXPECT_EQ(cache.stats().skipped, 1u);
    EXPECT_FALSE(cache.Get(0).ok());
}

TEST(BrickCache, AWriteErrorStopsTheCachingAndKeepsWhatWasCached) {
    BrickCache cache(NewSpillFile(), 3, uint64_t(1) << 30);
    cache.Put(0, TwoTriangles(true, true));
    ASSERT_TRUE(cache.Has(0));
    // A file size limit makes the next writes fail as a full disk would.
    {
        test::ScopedFileSizeLimit limit(1);
        ASSERT_TRUE(limit.ok());
        cache.Put(1, TwoTriangles(true, true));
    }
    EXPECT_FALSE(cache.Has(1));
    cache.Put(2, TwoTriangles(false, false));  // no more caching after a failure
    EXPECT_FALSE(cache.Has(2));
    EXPECT_EQ(cache.stats().skipped, 2u);
    auto mesh = cache.Get(0);
    ASSERT_TRUE(mesh.ok());
    ExpectSameMesh(*mesh, TwoTriangles(true, true));
}

}  // namespace
}  // namespace nave::render
