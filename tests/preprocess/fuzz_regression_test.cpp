// Inputs on which a fuzz target (tests/fuzz, docs/fuzzing.md) found an importer crashing or
// reporting undefined behaviour, each kept as found in tests/fixtures/models/fuzz/: they must now
// give an error naming the file and the problem. Run under the asan preset, the sanitizers check
// the rest.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "preprocess/import/importer.h"
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

}  // namespace
}  // namespace nave::preprocess
