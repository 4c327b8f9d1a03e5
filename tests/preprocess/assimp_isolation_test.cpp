// Assimp runs in a child process: files on which Assimp 5.2 aborts (mutations of square.off found
// by byte flips and truncations) give an error naming the file and the signal, and `nave
// preprocess` exits non-zero without leaving a store. Also the byte stream that carries the model
// back.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "common/run_nave.h"
#include "preprocess/import/assimp_importer.h"
#include "preprocess/import/importer.h"
#include "preprocess/import/model_wire.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using testing::Fixture;
using ::testing::HasSubstr;

const char* const kAbortingOffFiles[] = {"square_abort_truncated.off", "square_abort_flipped.off",
                                         "square_abort_44_vertices.off"};

TEST(AssimpIsolation, AnAbortInAssimpIsAnErrorNamingTheFileAndTheSignal) {
    for (const char* name : kAbortingOffFiles) {
        SCOPED_TRACE(name);
        auto source = OpenModel(Fixture(name));
        ASSERT_FALSE(source.ok());
        EXPECT_EQ(source.status().code(), StatusCode::kDataLoss);
        const std::string& m = source.status().message();
        EXPECT_THAT(m, HasSubstr(Fixture(name).string() +
                                 ": the Assimp importer crashed (signal 6: Aborted)"));
        EXPECT_THAT(m, HasSubstr("Assimp said: ai_assert failure"));
    }
}

// Damaged OFF files on which fuzz_assimp_in_process found Assimp 5.2 crashing outright: a bus error
// in its post-processing and a segmentation fault in its OFF reader.
TEST(AssimpIsolation, ACrashInAssimpIsAnErrorNamingTheSignal) {
    const std::pair<const char*, const char*> kCrashes[] = {
        {"fuzz/assimp_bus_error.off", "crashed (signal 7: Bus error)"},
        {"fuzz/assimp_segfault.off", "crashed (signal 11: Segmentation fault)"}};
    for (const auto& [name, crashed] : kCrashes) {
        SCOPED_TRACE(name);
        auto source = OpenModel(Fixture(name));
        ASSERT_FALSE(source.ok());
        EXPECT_EQ(source.status().code(), StatusCode::kDataLoss);
        EXPECT_THAT(source.status().message(),
                    HasSubstr(Fixture(name).string() + ": the Assimp importer " + crashed));
        const auto r =
            test::RunNave("preprocess " + Fixture(name).string() + " -o " +
                          (std::filesystem::temp_directory_path() / "never.nave").string());
        EXPECT_EQ(r.exit_code, 1) << r.output;
        EXPECT_THAT(r.output, HasSubstr(crashed));
    }
}

TEST(AssimpIsolation, TheIsolatedImportStillReadsGoodFiles) {
    std::unique_ptr<TriangleSource> source;
    auto tris = testing::ReadModel(Fixture("square.off"), &source);
    ASSERT_EQ(tris.size(), 2u);
    EXPECT_EQ(source->name(), "square.off");
    // A file Assimp refuses cleanly keeps Assimp's own message and the importer's code.
    const auto dir = testing::MakeTempDir("assimp_refused");
    { std::ofstream(dir / "empty_mesh.off") << "OFF\n0 0 0\n"; }
    auto refused = OpenWithAssimp(dir / "empty_mesh.off");
    EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(
        refused.status().message(),
        HasSubstr("empty_mesh.off: Assimp cannot read it: OFF: There are no valid vertices"));
    std::filesystem::remove_all(dir);
}

TEST(AssimpIsolation, NavePreprocessExitsNonZeroAndWritesNoStore) {
    const auto dir = testing::MakeTempDir("assimp_isolation");
    for (const char* name : kAbortingOffFiles) {
        SCOPED_TRACE(name);
        const std::filesystem::path out = dir / "out.nave";
        const auto r =
            test::RunNave("preprocess " + Fixture(name).string() + " -o " + out.string());
        EXPECT_EQ(r.exit_code, 1) << r.output;  // 1: bad data; -1 would mean nave itself was killed
        EXPECT_THAT(r.output, HasSubstr("nave: error: "));
        EXPECT_THAT(
            r.output,
            HasSubstr(name + std::string(": the Assimp importer crashed (signal 6: Aborted)")));
        EXPECT_FALSE(std::filesystem::exists(out));
    }
    std::filesystem::remove_all(dir);
}

ImportedModel SmallModel() {
    ImportedModel model;
    store::MaterialRecord m;
    m.name = "brass";
    m.diffuse = {0.7f, 0.5f, 0.2f};
    m.ior = 1.7f;
    m.textures["map_Kd"] = "brass.png";
    model.materials = {m, store::MaterialRecord{}};
    IndexedMesh mesh;
    mesh.where = "part.fbx mesh 0";
    mesh.material = 1;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    mesh.indices = {0, 1, 2, 2, 1, 3};
    model.meshes = {mesh, IndexedMesh{}};
    return model;
}

TEST(ModelWire, RoundTripKeepsEverything) {
    const ImportedModel model = SmallModel();
    auto decoded = DecodeImportedModel(EncodeImportedModel(model), "part.fbx");
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    EXPECT_EQ(decoded->materials, model.materials);
    ASSERT_EQ(decoded->meshes.size(), 2u);
    const IndexedMesh& a = decoded->meshes[0];
    EXPECT_EQ(a.where, "part.fbx mesh 0");
    EXPECT_EQ(a.material, 1u);
    EXPECT_EQ(a.positions, model.meshes[0].positions);
    EXPECT_EQ(a.normals, model.meshes[0].normals);
    EXPECT_TRUE(a.uvs.empty());
    EXPECT_EQ(a.indices, model.meshes[0].indices);
    EXPECT_TRUE(decoded->meshes[1].positions.empty());
}

TEST(ModelWire, EveryTruncationAndADamagedCountIsDataLoss) {
    const std::string bytes = EncodeImportedModel(SmallModel());
    for (size_t n = 0; n < bytes.size(); ++n) {
        auto decoded = DecodeImportedModel(bytes.substr(0, n), "part.fbx");
        ASSERT_FALSE(decoded.ok()) << "cut at " << n;
        EXPECT_EQ(decoded.status().code(), StatusCode::kDataLoss);
        EXPECT_THAT(decoded.status().message(),
                    HasSubstr("part.fbx: the model sent by the importer"));
    }
    // The material count (after the 8-byte magic) made huge: refused before any allocation.
    std::string huge = bytes;
    const uint64_t count = uint64_t(1) << 60;
    std::memcpy(&huge[8], &count, 8);
    auto decoded = DecodeImportedModel(huge, "part.fbx");
    EXPECT_THAT(decoded.status().message(), HasSubstr("of materials but only"));
    // Normals that do not match the positions would be read past their end.
    ImportedModel bad = SmallModel();
    bad.meshes[0].normals.pop_back();
    decoded = DecodeImportedModel(EncodeImportedModel(bad), "part.fbx");
    EXPECT_THAT(decoded.status().message(), HasSubstr("4 positions but 3 normals"));
    EXPECT_THAT(DecodeImportedModel(bytes + "x", "part.fbx").status().message(),
                HasSubstr("1 bytes follow the model"));
}

}  // namespace
}  // namespace nave::preprocess
