// Inputs on which a fuzz target (tests/fuzz, docs/fuzzing.md) found an importer crashing or
// reporting undefined behaviour, each kept as found in tests/fixtures/models/fuzz/: they must now
// give an error naming the file and the problem. Run under the asan preset, the sanitizers check
// the rest.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

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

// What a file and a store's piece give when read: the error of reading a fixture whole
// (ReadScalarGrid), and of reading its bytes as a piece (ReadScalarGridBytes).
struct VdbReadErrors {
    std::string file, bytes;
};
VdbReadErrors ReadVdbFixture(const std::string& name) {
    const std::filesystem::path file = Fixture("../volumes/" + name);
    StatusOr<const volumes::VdbPlugin*> plugin = volumes::LoadVdbPlugin();
    EXPECT_TRUE(plugin.ok()) << plugin.status().ToString();
    if (!plugin.ok()) return {};
    VdbReadErrors errors;
    auto whole = (*plugin)->ReadScalarGrid(file, "density");
    errors.file = whole.ok() ? "read" : whole.status().message();
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto piece = (*plugin)->ReadScalarGridBytes(
        {reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()}, "the piece");
    errors.bytes = piece.ok() ? "read" : piece.status().message();
    return errors;
}

// dust.vdb mutated by fuzz_vdb: its tree keeps nodes but no active voxel. OpenVDB's box of the
// active voxels is then inverted, +-2^31 voxels, which nave took for the grid's bounds: every ray
// marched ~1.7e10 m of empty leaves (10 s a ray). A grid without active voxels is now an error.
TEST(FuzzRegression, VdbGridWithoutActiveVoxelsIsAnError) {
    const VdbReadErrors errors = ReadVdbFixture("no_active_voxels.vdb");
    EXPECT_THAT(errors.file,
                HasSubstr("no_active_voxels.vdb: grid 'density' has no active voxels"));
}

// dust.vdb mutated: a grid descriptor's name claims 4 GiB. OpenVDB allocated and zeroed 4 GiB
// for it before finding the file short; nave's layout check refuses the length first.
TEST(FuzzRegression, VdbNameLongerThanTheFileIsAnError) {
    const VdbReadErrors errors = ReadVdbFixture("descriptor_name_4gib.vdb");
    EXPECT_THAT(errors.file, HasSubstr("descriptor_name_4gib.vdb: damaged: grid descriptor 0's "));
    EXPECT_THAT(errors.file, HasSubstr("past the end"));
    EXPECT_THAT(errors.bytes, HasSubstr("the piece: damaged: grid descriptor 0's "));
}

// A piece whose grid metadata holds a string of 4 GiB: OpenVDB's Stream allocated it.
TEST(FuzzRegression, VdbMetadataLongerThanTheBytesIsAnError) {
    const VdbReadErrors errors = ReadVdbFixture("metadata_string_4gib.vdb");
    EXPECT_THAT(errors.bytes, HasSubstr("the piece: damaged: grid 'density' metadata "));
    EXPECT_THAT(errors.file, HasSubstr("metadata_string_4gib.vdb"));
    EXPECT_NE(errors.file, "read");
}

// A piece announcing millions of grids: OpenVDB's Stream reserved a descriptor for each.
TEST(FuzzRegression, VdbStreamWithManyGridsIsAnError) {
    const VdbReadErrors errors = ReadVdbFixture("stream_grid_count_damaged.vdb");
    EXPECT_THAT(errors.bytes, HasSubstr("the piece: "));
    EXPECT_NE(errors.bytes, "read");
    EXPECT_THAT(errors.file, HasSubstr("stream_grid_count_damaged.vdb"));
}

}  // namespace
}  // namespace nave::preprocess
