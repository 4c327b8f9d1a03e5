// Inputs on which a fuzz target (tests/fuzz, docs/fuzzing.md) found an importer crashing or
// reporting undefined behaviour, each kept as found in tests/fixtures/models/fuzz/: they must now
// give an error naming the file and the problem. Run under the asan preset, the sanitizers check
// the rest.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/sanitizers.h"
#include "preprocess/import/importer.h"
#include "src/volumes/vdb_plugin.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using testing::Fixture;
using ::testing::HasSubstr;

// node_transform.glb mutated: accessor 0's componentType 5126 (FLOAT) became 5127, which no glTF
// type has. tinygltf gives -1 bytes per component; the importer's bounds check multiplied that into
// a size near 2^64, wrapped around, passed, and read before the buffer.
TEST(FuzzRegression, GltfUnknownComponentTypeIsAnError) {
    const std::string error = testing::ReadError(Fixture("fuzz/gltf_component_type_5127.glb"));
    EXPECT_THAT(error, HasSubstr("gltf_component_type_5127.glb: accessor 0 has an invalid "
                                 "componentType 5127"));
}

// A GLB whose JSON, damaged by fuzz_gltf, makes tinygltf index an empty array with at(): the
// std::out_of_range it throws went through nave to std::terminate.
TEST(FuzzRegression, GltfIndexOutOfRangeIsAnError) {
    const std::string error = testing::ReadError(Fixture("fuzz/gltf_out_of_range.glb"));
    EXPECT_THAT(error, HasSubstr("gltf_out_of_range.glb: not a valid glTF 2.0 file: the glTF "
                                 "reader failed on it (vector::_M_range_check"));
}

// A binary PLY whose header, damaged, declares an element of 8375319363688624582 records and no
// properties: the importer skipped the records one by one, zero bytes each, and never ended (a
// libFuzzer timeout). Such records are now skipped at once, and the file ends in an error.
TEST(FuzzRegression, PlyElementWithoutPropertiesEnds) {
    const std::string error =
        testing::ReadError(Fixture("fuzz/ply_element_without_properties.ply"));
    EXPECT_THAT(error, HasSubstr("ply_element_without_properties.ply"));
}

// dust.vdb (`nave generate dust --voxel 8`) mutated by fuzz_vdb: a leaf's Blosc block header gives
// a size of 128 TiB, which OpenVDB 10 allocates before it reads the block. A release build's
// allocation throws std::bad_alloc or the block fails to decompress: either is an error naming the
// file. Under ASan the allocation itself is fatal, inside libopenvdb (docs/fuzzing.md).
TEST(FuzzRegression, DamagedVdbBlockIsAnError) {
    if (NAVE_TEST_UNDER_ASAN) GTEST_SKIP() << "ASan ends OpenVDB's oversized allocation as fatal";
    const std::filesystem::path file = Fixture("../volumes/blosc_size_damaged.vdb");
    StatusOr<const volumes::VdbPlugin*> plugin = volumes::LoadVdbPlugin();
    ASSERT_TRUE(plugin.ok()) << plugin.status().ToString();
    auto whole = (*plugin)->ReadScalarGrid(file, "density");
    EXPECT_FALSE(whole.ok());
    EXPECT_THAT(whole.status().message(), HasSubstr("blosc_size_damaged.vdb"));
    const Bounds3f everywhere(Vec3f(-1e3f, -1e3f, -1e3f), Vec3f(1e3f, 1e3f, 1e3f));
    auto cut =
        (*plugin)->CutScalarGrid(file, "density", {&everywhere, 1}, /*memory_limit=*/0,
                                 [](size_t, const volumes::GridPiece&) { return Status::Ok(); });
    EXPECT_FALSE(cut.ok());
    EXPECT_THAT(cut.status().message(), HasSubstr("blosc_size_damaged.vdb"));
}

}  // namespace
}  // namespace nave::preprocess
