// Importers on small hand-made fixtures (tests/fixtures/models/make_fixtures.py writes them): every
// odd case of each format, the triangles they yield, and the errors and warnings bad input gives.

#include "preprocess/import/importer.h"

#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <random>

#include "preprocess/import/triangle_check.h"
#include "src/core/file.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using testing::Area;
using testing::Fixture;
using ::testing::HasSubstr;
using testing::ReadError;
using testing::ReadModel;

Vec3d Normal(const Triangle& t) {
    Vec3d a(t.p[0]), b(t.p[1]), c(t.p[2]);
    return Normalize(Cross(b - a, c - a));
}

TEST(ObjImporter, CrlfQuadsNgonsNegativeIndicesAndMaterials) {
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(Fixture("shapes_crlf.obj"), &source);
    // quad -> 2, pentagon -> 3, triangle -> 1.
    ASSERT_EQ(tris.size(), 6u);
    const auto& mats = source->materials();
    ASSERT_EQ(mats.size(), 3u);
    EXPECT_EQ(mats[tris[0].material].name, "red");
    EXPECT_FLOAT_EQ(mats[tris[0].material].diffuse[0], 0.8f);
    EXPECT_EQ(mats[tris[0].material].textures.at("map_Kd"), "missing_texture.png");
    EXPECT_EQ(mats[tris[2].material].name, "blue");
    EXPECT_FLOAT_EQ(mats[tris[2].material].opacity, 0.5f);
    EXPECT_EQ(mats[tris[5].material].name, "undefined_in_mtl");
    // The quad keeps its texture coordinates and normals; the pentagon has neither.
    EXPECT_TRUE(tris[0].has_uvs && tris[0].has_normals);
    EXPECT_FLOAT_EQ(tris[0].uv[1][0], 1.f);
    EXPECT_FALSE(tris[2].has_uvs || tris[2].has_normals);
    EXPECT_TRUE(tris[5].has_normals && !tris[5].has_uvs);
    // Areas: unit quad, pentagon (0,0)(2,0)(3,1)(1,2)(-1,1) by the shoelace formula = 5.
    EXPECT_NEAR(Area(tris[0]) + Area(tris[1]), 1.0, 1e-6);
    EXPECT_NEAR(Area(tris[2]) + Area(tris[3]) + Area(tris[4]), 5.0, 1e-6);
    // Relative indices -5 -4 -3 after 9 vertices are vertices 5, 6, 7 (1-based).
    EXPECT_EQ(tris[5].p[0], Vec3f(0, 0, 1));
    EXPECT_EQ(tris[5].p[2], Vec3f(3, 1, 1));
    for (const auto& t : tris) EXPECT_GT(Normal(t).z, 0.99);  // counter-clockwise seen from +z
    EXPECT_EQ(
        source->warnings().Count("materials used but defined in no MTL (default colour used)"), 1u);
}

TEST(ObjImporter, ConcavePolygonsAreEarClipped) {
    auto tris = ReadModel(Fixture("l_shape.obj"));
    ASSERT_EQ(tris.size(), 4u);
    double area = 0;
    for (const auto& t : tris) {
        area += Area(t);
        EXPECT_GT(Normal(t).z, 0.99);  // winding kept
        // Every triangle inside the L: its centroid is not in the missing square [1, 2] x [1, 2].
        Vec3f c = (t.p[0] + t.p[1] + t.p[2]) * (1.f / 3);
        EXPECT_FALSE(c.x > 1 && c.y > 1) << "triangle outside the polygon";
    }
    EXPECT_NEAR(area, 3.0, 1e-6);  // a fan from corner (2, 1) would give 4
}

TEST(ObjImporter, MissingMtlIsOneWarningAndADefaultMaterial) {
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(Fixture("missing_mtl.obj"), &source);
    ASSERT_EQ(tris.size(), 1u);
    EXPECT_EQ(source->warnings().Count("missing MTL files (default materials used)"), 1u);
    EXPECT_EQ(source->materials().at(tris[0].material).name, "default");
    EXPECT_THAT(source->warnings().Summary()[0], HasSubstr("missing_mtl.obj:1"));
}

TEST(ObjImporter, BadIndicesNameFileAndLine) {
    EXPECT_THAT(ReadError(Fixture("bad_index.obj")),
                HasSubstr("bad_index.obj:5: face vertex index 4 out of range"));
    EXPECT_THAT(ReadError(Fixture("zero_index.obj")),
                HasSubstr("zero_index.obj:4: face vertex index 0"));
    EXPECT_THAT(ReadError(Fixture("malformed.obj")),
                HasSubstr("malformed.obj:2: 'v' expects 3 numbers, found 'zero'"));
}

TEST(ObjImporter, NanAndDegenerateFacesAreCountedWarnings) {
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(Fixture("nan_degenerate.obj"), &source);
    EXPECT_EQ(tris.size(), 1u);  // f 1 2 3 (f 1 2 5 is collinear: degenerate)
    EXPECT_EQ(source->warnings().Count(kWarnNonFinite), 1u);
    EXPECT_EQ(source->warnings().Count(kWarnDegenerate), 2u);
    bool found = false;
    for (const auto& line : source->warnings().Summary()) {
        if (line.find("degenerate faces") != std::string::npos) {
            EXPECT_THAT(line, HasSubstr("2 (first at nan_degenerate.obj:8)"));
            found = true;
        }
    }
    EXPECT_TRUE(found);
}

TEST(ObjImporter, EmptyAndGarbageFilesAreErrors) {
    EXPECT_THAT(ReadError(Fixture("empty.obj")), HasSubstr("empty.obj: empty file"));
    EXPECT_THAT(ReadError(Fixture("comments_only.obj")), HasSubstr("no faces found"));
    EXPECT_THAT(ReadError(Fixture("garbage.obj")), HasSubstr("garbage.obj:1: "));
    EXPECT_THAT(ReadError(Fixture("unknown.xyz")), HasSubstr("unknown model format '.xyz'"));
    EXPECT_THAT(ReadError(Fixture("does_not_exist.obj")), HasSubstr("no such file"));
}

TEST(PlyImporter, AsciiWithExtraPropertiesAndQuads) {
    auto tris = ReadModel(Fixture("tetra_ascii.ply"));
    ASSERT_EQ(tris.size(), 5u);  // 3 triangles + a quad
    EXPECT_EQ(tris[0].p[1], Vec3f(0, 1, 0));
    EXPECT_EQ(tris[0].p[2], Vec3f(1, 0, 0));
    EXPECT_LT(Normal(tris[0]).z, -0.99);  // face 0 2 1 looks down (outward for the tetrahedron)
}

TEST(PlyImporter, BigEndianTriangleStripsWithRestarts) {
    auto tris = ReadModel(Fixture("strips_big.ply"));
    ASSERT_EQ(tris.size(), 4u);
    // Run 0 1 2 3: (0 1 2), then (1 2 3) flipped to (2 1 3) to keep the winding; run 2 3 4 5 5
    // after the restart: (2 3 4), (4 3 5), and (4 5 5) dropped.
    EXPECT_EQ(tris[0].p[0], Vec3f(0, 0, 0));
    EXPECT_EQ(tris[1].p[0], Vec3f(0, 1, 0));
    EXPECT_EQ(tris[1].p[1], Vec3f(1, 0, 0));
    EXPECT_EQ(tris[2].p[0], Vec3f(0, 1, 0));
    EXPECT_EQ(tris[3].p[0], Vec3f(0, 2, 0));
    for (const auto& t : tris) EXPECT_GT(Normal(t).z, 0.99) << "strip winding must alternate";
}

TEST(PlyImporter, LittleEndianFaces) {
    auto tris = ReadModel(Fixture("faces_little.ply"));
    ASSERT_EQ(tris.size(), 3u);
    double area = 0;
    for (const auto& t : tris) area += Area(t);
    EXPECT_NEAR(area, 0.5 + 1.0, 1e-6);
}

TEST(PlyImporter, ErrorsNameFileAndPlace) {
    EXPECT_THAT(ReadError(Fixture("bad_index.ply")),
                HasSubstr("bad_index.ply:13: face 0 vertex index 9 out of range [0, 3)"));
    EXPECT_THAT(ReadError(Fixture("truncated.ply")), HasSubstr("truncated.ply @"));
    EXPECT_THAT(ReadError(Fixture("truncated.ply")), HasSubstr("truncated"));
    EXPECT_THAT(
        ReadError(
            Fixture("garbage.obj").replace_filename("strips_big.ply").replace_extension(".ply")),
        ::testing::IsEmpty());
}

// A vertex count far beyond what the file holds (damage, or a header written before the data) is
// not allocated up front: the file ends first, in an error naming it.
TEST(PlyImporter, HugeVertexCountIsNotAllocated) {
    const auto dir = testing::MakeTempDir("ply_huge_count");
    {
        std::ofstream(dir / "huge.ply", std::ios::binary)
            << "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\nproperty float "
               "x\n"
               "property float y\nproperty float z\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n"
            << std::string(12 * 3, '\0');
    }
    EXPECT_THAT(ReadError(dir / "huge.ply"), HasSubstr("huge.ply"));
    EXPECT_THAT(ReadError(dir / "huge.ply"), HasSubstr("truncated"));
    std::filesystem::remove_all(dir);
}

TEST(StlImporter, BinaryStartingWithSolidIsReadAsBinary) {
    auto tris = ReadModel(Fixture("solid_binary.stl"));
    ASSERT_EQ(tris.size(), 3u);
    EXPECT_EQ(tris[1].p[2], Vec3f(0, 0, 1));
}

TEST(StlImporter, AsciiWithCrlf) {
    auto binary = ReadModel(Fixture("solid_binary.stl"));
    auto ascii = ReadModel(Fixture("ascii.stl"));
    ASSERT_EQ(ascii.size(), binary.size());
    for (size_t i = 0; i < ascii.size(); ++i) EXPECT_EQ(ascii[i].p, binary[i].p);
}

TEST(StlImporter, TruncatedBinaryNamesSizes) {
    EXPECT_THAT(ReadError(Fixture("truncated.stl")),
                HasSubstr("binary STL header says 3 triangles, so 234 bytes expected, found 224"));
}

TEST(GltfImporter, NodeTransformsAndMaterials) {
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(Fixture("node_transform.gltf"), &source);
    ASSERT_EQ(tris.size(), 1u);
    // World = scale 2 * translate (10, 0, 0): vertex (1, 0, 0) -> (22, 0, 0).
    EXPECT_EQ(tris[0].p[0], Vec3f(20, 0, 0));
    EXPECT_EQ(tris[0].p[1], Vec3f(22, 0, 0));
    EXPECT_EQ(tris[0].p[2], Vec3f(20, 2, 0));
    ASSERT_TRUE(tris[0].has_normals);
    EXPECT_NEAR(tris[0].n[0].z, 1.f, 1e-6f);
    const auto& m = source->materials().at(tris[0].material);
    EXPECT_EQ(m.name, "brass");
    EXPECT_FLOAT_EQ(m.diffuse[1], 0.7f);
    EXPECT_FLOAT_EQ(m.metallic, 1.f);
    EXPECT_FLOAT_EQ(m.roughness, 0.3f);
    EXPECT_FLOAT_EQ(m.emission[2], 0.3f);
    EXPECT_EQ(m.textures.at("baseColorTexture"), "brass.png");
    EXPECT_EQ(source->units(), "m");
}

// glTF 2.0 §3.9.4: alphaMode MASK cuts the surface out where base-colour alpha is below
// alphaCutoff; the importer keeps the cutoff and names the base-colour image as the alpha source.
TEST(GltfImporter, AlphaMaskKeepsCutoffAndAlphaSource) {
    std::string text = ReadFileToString(Fixture("node_transform.gltf")).value();
    const std::string name = "\"name\": \"brass\",";
    ASSERT_NE(text.find(name), std::string::npos);
    text.replace(text.find(name), name.size(),
                 name + " \"alphaMode\": \"MASK\", \"alphaCutoff\": 0.3,");
    auto dir = testing::MakeTempDir("gltf_mask");
    std::ofstream(dir / "mask.gltf") << text;
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(dir / "mask.gltf", &source);
    ASSERT_EQ(tris.size(), 1u);
    const auto& m = source->materials().at(tris[0].material);
    EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3f);
    EXPECT_EQ(m.textures.at("alphaMask"), "brass.png");
    // Without MASK there is no alpha source and the default cutoff.
    auto plain = ReadModel(Fixture("node_transform.gltf"), &source);
    const auto& p = source->materials().at(plain[0].material);
    EXPECT_EQ(p.textures.count("alphaMask"), 0u);
    EXPECT_FLOAT_EQ(p.alpha_cutoff, 0.5f);
}

// RFC 4648 base64, for building data URIs in tests.
std::string Base64(const std::string& bytes) {
    static const char kAlphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const size_t rem = std::min<size_t>(3, bytes.size() - i);
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (rem > 1) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (rem > 2) v |= uint32_t(uint8_t(bytes[i + 2]));
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += rem > 1 ? kAlphabet[(v >> 6) & 63] : '=';
        out += rem > 2 ? kAlphabet[v & 63] : '=';
    }
    return out;
}

// An image embedded in the file (a data URI here; GLB buffer views take the same path) gets a name,
// and the source writes its bytes under that name for the texture conversion.
TEST(GltfImporter, EmbeddedImageIsWrittenForTheTextureConversion) {
    auto dir = testing::MakeTempDir("gltf_embedded");
    // A real 2 x 1 PNG written by OpenImageIO.
    {
        auto out = OIIO::ImageOutput::create((dir / "src.png").string());
        ASSERT_TRUE(out);
        const uint8_t px[6] = {255, 0, 0, 0, 0, 255};
        ASSERT_TRUE(
            out->open((dir / "src.png").string(), OIIO::ImageSpec(2, 1, 3, OIIO::TypeUInt8)));
        ASSERT_TRUE(out->write_image(OIIO::TypeUInt8, px));
        ASSERT_TRUE(out->close());
    }
    const std::string png = ReadFileToString(dir / "src.png").value();
    std::string text = ReadFileToString(Fixture("node_transform.gltf")).value();
    const std::string uri = "\"uri\": \"brass.png\"";
    ASSERT_NE(text.find(uri), std::string::npos);
    text.replace(text.find(uri), uri.size(),
                 "\"uri\": \"data:image/png;base64," + Base64(png) + "\"");
    std::ofstream(dir / "inline.gltf") << text;
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(dir / "inline.gltf", &source);
    ASSERT_EQ(tris.size(), 1u);
    const auto& m = source->materials().at(tris[0].material);
    EXPECT_EQ(m.textures.at("baseColorTexture"), "inline.image0.png");
    auto out = dir / "generated";
    std::filesystem::create_directories(out);
    ASSERT_TRUE(source->WriteGeneratedTextures(out).ok());
    EXPECT_EQ(ReadFileToString(out / "inline.image0.png").value(), png);
}

TEST(GltfImporter, BinaryGlbGivesTheSameTriangle) {
    auto text = ReadModel(Fixture("node_transform.gltf"));
    auto binary = ReadModel(Fixture("node_transform.glb"));
    ASSERT_EQ(binary.size(), 1u);
    EXPECT_EQ(binary[0].p, text[0].p);
}

TEST(AssimpImporter, OtherFormatsThroughAssimp) {
    std::unique_ptr<TriangleSource> source;
    auto tris = ReadModel(Fixture("square.off"), &source);
    ASSERT_EQ(tris.size(), 2u);  // the quad, triangulated
    EXPECT_NEAR(Area(tris[0]) + Area(tris[1]), 1.0, 1e-6);
    EXPECT_EQ(source->units(), "unknown");
}

TEST(MergedInputs, MaterialNamesAreMadeUnique) {
    auto source =
        OpenModels({Fixture("shapes_crlf.obj"), Fixture("shapes_crlf.obj"), Fixture("ascii.stl")});
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    auto tris = ReadAll(**source);
    ASSERT_TRUE(tris.ok());
    EXPECT_EQ(tris->size(), 6u + 6u + 3u);
    std::vector<std::string> names;
    for (const auto& m : (*source)->materials()) names.push_back(m.name);
    EXPECT_THAT(names, ::testing::UnorderedElementsAre("red", "blue", "undefined_in_mtl", "red.1",
                                                       "blue.1", "undefined_in_mtl.1", "default"));
    EXPECT_EQ((*source)->materials()[(*tris)[6].material].name, "red.1");
}

}  // namespace
}  // namespace nave::preprocess

namespace nave::preprocess {
namespace {

// Garbage and every truncation of valid files: each read ends in an error or a model, never a
// crash.
TEST(ImporterRobustness, GarbageAndTruncationsNeverCrash) {
    auto dir = testing::MakeTempDir("garbage");
    std::mt19937 rng(99);
    int errors = 0;
    for (const char* ext : {".obj", ".ply", ".stl", ".gltf", ".glb"}) {
        for (int i = 0; i < 12; ++i) {
            std::string bytes(size_t(rng() % 600), '\0');
            for (char& c : bytes) c = char(rng());
            if (i % 4 == 1)
                bytes.insert(
                    0,
                    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n");
            if (i % 4 == 2) bytes.insert(0, "solid x\n");
            if (i % 4 == 3) bytes.insert(0, "v 1 2 3\nf 1 1 1\n");
            auto path = dir / (std::to_string(i) + ext);
            std::FILE* f = std::fopen(path.c_str(), "wb");
            std::fwrite(bytes.data(), 1, bytes.size(), f);
            std::fclose(f);
            if (!ReadError(path).empty()) ++errors;
        }
    }
    EXPECT_GT(errors, 50);  // nearly all garbage is refused with a message
    for (const char* name : {"faces_little.ply", "strips_big.ply", "solid_binary.stl",
                             "shapes_crlf.obj", "tetra_ascii.ply", "node_transform.glb"}) {
        auto bytes = ReadFileToString(Fixture(name));
        ASSERT_TRUE(bytes.ok());
        std::string ext = std::filesystem::path(name).extension().string();
        for (size_t cut = 0; cut < bytes->size(); cut += (cut + 16 < bytes->size() ? 5 : 1)) {
            auto path = dir / ("cut" + ext);
            std::FILE* f = std::fopen(path.c_str(), "wb");
            std::fwrite(bytes->data(), 1, cut, f);
            std::fclose(f);
            (void)ReadError(path);  // must return, whatever it says
        }
    }
    std::filesystem::remove_all(dir);
}

// DXF through Assimp: 3DFACE and polyface-mesh entities, each layer (and each colour within it) a
// material named after the layer.
TEST(DxfInput, LayersBecomeMaterials) {
    std::unique_ptr<TriangleSource> source;
    const std::vector<Triangle> triangles =
        testing::ReadModel(testing::Fixture("dxf/layers.dxf"), &source);
    ASSERT_TRUE(source);
    std::map<std::string, int> per_name;
    for (const Triangle& t : triangles) ++per_name[source->materials().at(t.material).name];
    // Walls: two quads of colour 1 (red), one triangle of colour 3; Roof: a quad with a repeated
    // corner; Vault: a polyface mesh of two triangles.
    EXPECT_EQ(per_name["Walls"], 4);
    EXPECT_EQ(per_name["Walls #2"], 1);
    EXPECT_EQ(per_name["Roof"], 1);
    EXPECT_EQ(per_name["Vault"], 2);
    for (const auto& m : source->materials()) {
        if (m.name == "Walls") {
            EXPECT_EQ(m.diffuse, (std::array<float, 3>{1.f, 0.f, 0.f}));
        }
    }
}

// MESH entities, which Assimp does not read, are read by nave: a drawing of them alone, each layer
// a material, a concave face cut by ear clipping (area 3, not the fan's).
TEST(DxfInput, MeshEntitiesAreReadByNave) {
    std::unique_ptr<TriangleSource> source;
    const std::vector<Triangle> triangles =
        testing::ReadModel(testing::Fixture("dxf/mesh.dxf"), &source);
    ASSERT_TRUE(source);
    std::map<std::string, double> area;
    std::map<std::string, int> count;
    for (const Triangle& t : triangles) {
        const std::string& name = source->materials().at(t.material).name;
        area[name] += testing::Area(t);
        ++count[name];
    }
    EXPECT_EQ(count["Apse"], 2);
    EXPECT_NEAR(area["Apse"], 1.0, 1e-6);
    EXPECT_EQ(count["Vault"], 4);
    EXPECT_NEAR(area["Vault"], 3.0, 1e-6);
}

// A MESH entity whose face names a vertex it does not have is an error naming the file and line.
TEST(DxfInput, ADamagedMeshEntityIsAnErrorNamingItsLine) {
    test::ScratchDir dir("dxf");
    const std::filesystem::path path = dir / "bad.dxf";
    std::ofstream(path) << "0\nSECTION\n2\nENTITIES\n0\nMESH\n8\nApse\n92\n3\n10\n0\n20\n0\n30\n0\n"
                           "10\n1\n20\n0\n30\n0\n10\n0\n20\n1\n30\n0\n93\n4\n90\n3\n90\n0\n90\n1\n"
                           "90\n9\n0\nENDSEC\n0\nEOF\n";
    const std::string error = testing::ReadError(path);
    EXPECT_THAT(
        error, ::testing::HasSubstr(path.string() + ":5: MESH entity: a face names vertex 9 of 3"));
}

// DWG is closed: nave refuses it, by extension or by its "AC10xx" signature, naming DXF as the way
// in, instead of handing it to Assimp or calling it an unknown format.
TEST(DwgInput, IsRefusedNamingAnExportToDxf) {
    test::ScratchDir dir("dwg");
    for (const char* name : {"plan.dwg", "plan.DWG", "plan.bin"}) {
        SCOPED_TRACE(name);
        const std::filesystem::path path = dir / name;
        std::ofstream(path, std::ios::binary) << "AC1032" << std::string(100, '\0');
        StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(path);
        ASSERT_FALSE(source.ok());
        EXPECT_EQ(source.status().code(), StatusCode::kUnsupported);
        EXPECT_THAT(source.status().message(), ::testing::HasSubstr(path.string()));
        EXPECT_THAT(source.status().message(), ::testing::HasSubstr("DXF"));
    }
}

}  // namespace
}  // namespace nave::preprocess
