// Write -> read round trips of the brick store: exact topology and material ids, positions within
// the grid's bound, normals and UVs within their quantization bounds, and no cracks between bricks.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <thread>

#include "store/brick_codec.h"
#include "store/face_shading.h"
#include "store/store_format.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "store/testing/store_testing.h"
#include "test_util.h"

namespace nave::store {
namespace {

using test::ScratchDir;
using test::SortedKeys;

// A grid whose origin is not on any round number, so that snapping really moves the vertices.
GlobalGrid TestGrid(double step = 1e-3) { return GlobalGrid{{-1.2345, 2.3456, -0.3579}, step}; }

// Bound on the angle-free error |n_decoded - n| of Draco's octahedral normal quantization with
// `bits` bits. The octahedral parameters (u, v) in [-1, 1] are quantized with step d = 2 / (2^bits
// - 1), so each moves by at most d/2. The unnormalized octahedron point (u, v, 1 - |u| - |v|) then
// moves by at most sqrt((d/2)^2 + (d/2)^2 + d^2) = d sqrt(1.5), and normalizing a vector of length
// >= 1/sqrt(3) (the octahedron's closest point to the origin) scales that by at most sqrt(3):
// |error| <= d sqrt(4.5). Octahedral mapping: Meyer et al., "On Floating-Point Normal Vectors",
// EGSR 2010, section 3.
double NormalErrorBound(int bits) { return 2.0 / ((1 << bits) - 1) * std::sqrt(4.5); }
// A derived normal lies within EncodeOptions::derived_normal_error_deg of the input's: the chord
// between the two unit vectors, plus float rounding.
double DerivedNormalErrorBound() {
    return 2 * std::sin(EncodeOptions().derived_normal_error_deg * M_PI / 360) + 1e-5;
}

// Draco quantizes each UV component on a uniform grid spanning the brick's largest UV range with
// 2^bits - 1 steps, so the error is at most half a step.
double UvErrorBound(int bits, double range) { return 0.5 * range / ((1 << bits) - 1); }

TEST(StoreRoundTrip, SurfaceSplitOnGridIsExact) {
    ScratchDir dir;
    testing::SurfaceOptions surface;
    surface.quads_x = 40;
    surface.quads_y = 30;
    const BrickMesh mesh = testing::MakeSurface(surface);
    const auto materials = testing::MakeMaterials(3);
    const GlobalGrid grid = TestGrid();
    const EncodeOptions options;
    auto written =
        testing::WriteGridStore(dir / "surface.nave", mesh, materials, {3, 2, 1}, grid, options);
    ASSERT_TRUE(written.ok()) << written.status().ToString();
    EXPECT_EQ(dir.Files(), std::vector<std::string>{"surface.nave"});

    auto opened = Store::Open(dir / "surface.nave");
    ASSERT_TRUE(opened.ok()) << opened.status().ToString();
    const Store& store = **opened;
    EXPECT_EQ(store.header().major, kFormatMajor);
    EXPECT_EQ(store.header().minor, kFormatMinor);
    EXPECT_EQ(store.header().grid.origin, grid.origin);
    EXPECT_EQ(store.header().grid.step, grid.step);
    EXPECT_EQ(store.header().triangle_count, mesh.TriangleCount());
    EXPECT_EQ(store.header().source_triangle_count, mesh.TriangleCount());
    EXPECT_EQ(store.header().provenance.source_files,
              std::vector<std::string>{"synthetic-surface"});
    EXPECT_EQ(store.header().provenance.tool_version, "nave test");
    EXPECT_EQ(store.header().provenance.options, "grid-split");
    EXPECT_EQ(store.materials(), materials);
    ASSERT_EQ(store.bricks().size(), written->bricks.size());
    ASSERT_EQ(store.bricks().size(), 6u);
    EXPECT_EQ(store.tree().nodes().size(), written->tree.nodes().size());

    // Where each grid point decodes, over all bricks: a vertex shared by two bricks must decode bit
    // for bit to the same coordinates in both.
    std::map<std::array<int32_t, 3>, std::pair<Vec3f, int>> decoded_at;
    Bounds3f all;
    for (uint32_t b = 0; b < store.bricks().size(); ++b) {
        SCOPED_TRACE("brick " + std::to_string(b));
        const BrickMesh& in = written->bricks[b];
        auto read = store.ReadBrick(b);
        ASSERT_TRUE(read.ok()) << read.status().ToString();
        const BrickMesh& out = *read;
        const BrickInfo& info = store.bricks()[b];

        // Topology and materials: the same oriented triangles on the grid, with the same materials.
        EXPECT_EQ(SortedKeys(out, grid, false), SortedKeys(in, grid, false));
        EXPECT_EQ(out.TriangleCount(), info.triangle_count);
        EXPECT_EQ(out.VertexCount(), info.vertex_count);
        EXPECT_EQ(out.MemoryBytes(), info.decoded_bytes);
        EXPECT_TRUE(out.HasNormals() && info.has_normals);
        EXPECT_TRUE(out.HasUvs() && info.has_uvs);

        // Positions within step/2 per axis (plus the float rounding of the decoded value).
        std::map<std::array<int32_t, 3>, uint32_t>
            input_vertex;  // the surface has one vertex per point
        for (uint32_t v = 0; v < in.VertexCount(); ++v)
            input_vertex[test::GridKey(grid, in.positions[v])] = v;
        float uv_lo = 1e30f, uv_hi = -1e30f;
        for (const auto& uv : in.uvs)
            uv_lo = std::min({uv_lo, uv[0], uv[1]}), uv_hi = std::max({uv_hi, uv[0], uv[1]});
        Bounds3f box;
        std::vector<uint8_t> flat_corner(out.VertexCount(), 0);
        for (uint32_t v = 0; v < out.VertexCount(); ++v) {
            const auto key = test::GridKey(grid, out.positions[v]);
            auto it = input_vertex.find(key);
            ASSERT_NE(it, input_vertex.end())
                << "decoded vertex " << v << " is on no input grid point";
            const uint32_t src = it->second;
            for (int a = 0; a < 3; ++a) {
                const double err =
                    std::fabs(double(out.positions[v][a]) - double(in.positions[src][a]));
                // Half a float ulp of the decoded value, which lies within step/2 of the input.
                const double round = (std::fabs(double(in.positions[src][a])) + grid.step) * 6e-8;
                EXPECT_LE(err, grid.MaxAxisError() + round) << "vertex " << v << " axis " << a;
            }
            const Vec3f n = in.normals[src];
            if (Length(out.normals[v]) == 0.f) {
                // A corner of flat faces only (their normal is the geometric one): checked below.
                flat_corner[v] = 1;
            } else {
                // Stored (quantized) or derived from the positions (within 1 degree).
                EXPECT_LE(
                    Length(out.normals[v] - n),
                    std::max(NormalErrorBound(options.normal_bits), DerivedNormalErrorBound()))
                    << "vertex " << v;
                EXPECT_NEAR(Length(out.normals[v]), 1.f, 1e-5f);
            }
            for (int c = 0; c < 2; ++c) {
                EXPECT_LE(std::fabs(out.uvs[v][c] - in.uvs[src][c]),
                          UvErrorBound(options.uv_bits, uv_hi - uv_lo) + 1e-7)
                    << "vertex " << v;
            }
            box.Extend(out.positions[v]);
            auto [slot, inserted] = decoded_at.try_emplace(key, out.positions[v], 0);
            EXPECT_EQ(slot->second.first, out.positions[v])
                << "grid point decodes differently in two bricks";
            slot->second.second += inserted ? 1 : 0;
        }
        EXPECT_EQ(box, info.geometry_bounds);
        // Corners stored without a normal belong to flat faces: the input normals there lie along
        // the face's geometric normal (within the encoder's 0.8 degrees).
        for (size_t t = 0; t < out.TriangleCount(); ++t) {
            const uint32_t* corner = &out.indices[3 * t];
            if (!flat_corner[corner[0]]) continue;
            const auto p = out.TrianglePositions(t);
            const Vec3f ng = Normalize(Cross(p[1] - p[0], p[2] - p[0]));
            for (int c = 0; c < 3; ++c) {
                EXPECT_TRUE(flat_corner[corner[c]]) << "triangle " << t << " mixes flat and smooth";
                const Vec3f n =
                    in.normals[input_vertex[test::GridKey(grid, out.positions[corner[c]])]];
                EXPECT_GE(std::fabs(Dot(Normalize(n), ng)), 0.9999f - 1e-4f) << "triangle " << t;
            }
        }
        EXPECT_TRUE(store.VerifyBrick(b).ok());
        all.Extend(box);
    }
    EXPECT_EQ(all, store.header().bounds);
    // Shared border vertices exist (otherwise the crack check above proved nothing).
    size_t shared = 0;
    std::map<std::array<int32_t, 3>, int> bricks_per_point;
    for (const BrickMesh& in : written->bricks) {
        std::set<std::array<int32_t, 3>> mine;
        for (const Vec3f& p : in.positions) mine.insert(test::GridKey(grid, p));
        for (const auto& k : mine) ++bricks_per_point[k];
    }
    for (const auto& [k, count] : bricks_per_point) shared += count > 1 ? 1 : 0;
    EXPECT_GT(shared, 50u);
    EXPECT_GT(store.bytes_read(), 0u);
}

// A brick with everything Draco finds awkward: a random material per triangle (vertices split
// between materials), an edge shared by three triangles, a duplicated triangle, vertices the input
// split for seams, isolated vertices, and triangles that collapse on the grid.
BrickMesh AwkwardMesh(std::mt19937& rng, uint32_t materials) {
    BrickMesh m = testing::MakeSurface({.quads_x = 12, .quads_y = 9, .material_count = 1});
    std::uniform_int_distribution<uint32_t> pick(0, materials - 1);
    for (uint32_t& id : m.material_ids) id = pick(rng);
    auto add_vertex = [&](Vec3f p) {
        m.positions.push_back(p);
        m.normals.push_back({0, 0, 1});
        m.uvs.push_back({0.5f, 0.5f});
        return uint32_t(m.positions.size() - 1);
    };
    auto add_triangle = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t material) {
        m.indices.insert(m.indices.end(), {a, b, c});
        m.material_ids.push_back(material);
    };
    // A fin on the edge (0, 1): three triangles share it.
    const uint32_t fin = add_vertex({0.4f, 0.f, 2.f});
    add_triangle(0, 1, fin, pick(rng));
    // The same triangle twice, with different materials.
    add_triangle(14, 15, 28, 0);
    add_triangle(14, 15, 28, materials - 1);
    // A seam copy of vertex 20 (same position, other normal), used by a new triangle.
    const uint32_t copy = add_vertex(m.positions[20]);
    m.normals[copy] = {1, 0, 0};
    add_triangle(copy, 21, fin, pick(rng));
    // Isolated vertices and a triangle whose corners are 1e-5 apart (inside one 1 mm grid cell).
    add_vertex({5, 5, 5});
    const uint32_t a = add_vertex({3.f, 3.f, 3.f}), b = add_vertex({3.f, 3.00001f, 3.f});
    add_triangle(a, b, 5, 1);
    return m;
}

TEST(StoreRoundTrip, AwkwardMeshKeepsEveryTriangleAndMaterial) {
    std::mt19937 rng(12345);
    const GlobalGrid grid = TestGrid();
    for (int speed : {0, 5, 10}) {
        SCOPED_TRACE("speed " + std::to_string(speed));
        const BrickMesh mesh = AwkwardMesh(rng, 7);
        EncodeOptions options;
        options.draco_speed = speed;
        auto encoded = EncodeBrick(mesh, Bounds3f({0, 0, 0}, {10, 10, 10}), grid, options);
        ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
        EXPECT_EQ(encoded->dropped_triangle_count, 1u);
        EXPECT_EQ(encoded->triangle_count, mesh.TriangleCount() - 1);
        EXPECT_EQ(encoded->max_material_id, 6u);
        auto decoded = codec::DecodeMeshSection(encoded->mesh_bytes, grid, 7, "test");
        ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
        EXPECT_EQ(SortedKeys(*decoded, grid, false), SortedKeys(mesh, grid, true));
        EXPECT_EQ(decoded->VertexCount(), encoded->vertex_count);
        EXPECT_EQ(decoded->MemoryBytes(), encoded->decoded_bytes);
    }
}

TEST(StoreRoundTrip, IrregularSurfaceAtEverySpeed) {
    const GlobalGrid grid = TestGrid();
    testing::SurfaceOptions surface;
    surface.quads_x = 20;
    surface.quads_y = 17;
    surface.jitter = 0.8f;
    surface.material_count = 4;
    const BrickMesh mesh = testing::MakeSurface(surface);
    for (int speed = 0; speed <= 10; ++speed) {
        SCOPED_TRACE("speed " + std::to_string(speed));
        EncodeOptions options;
        options.draco_speed = speed;
        auto encoded = EncodeBrick(mesh, {}, grid, options);
        ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
        auto decoded = codec::DecodeMeshSection(encoded->mesh_bytes, grid, 4, "test");
        ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
        EXPECT_EQ(SortedKeys(*decoded, grid, false), SortedKeys(mesh, grid, false));
    }
}

TEST(StoreRoundTrip, MeshWithoutNormalsOrUvs) {
    const GlobalGrid grid = TestGrid(0.01);
    const BrickMesh mesh =
        testing::MakeSurface({.quads_x = 8, .quads_y = 8, .normals = false, .uvs = false});
    auto encoded = EncodeBrick(mesh, Bounds3f({0, 0, 0}, {10, 10, 1}), grid, {});
    ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
    EXPECT_FALSE(encoded->has_normals);
    EXPECT_FALSE(encoded->has_uvs);
    auto decoded = codec::DecodeMeshSection(encoded->mesh_bytes, grid, 3, "test");
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    EXPECT_FALSE(decoded->HasNormals());
    EXPECT_FALSE(decoded->HasUvs());
    EXPECT_EQ(SortedKeys(*decoded, grid, false), SortedKeys(mesh, grid, false));
}

TEST(StoreRoundTrip, BrickWhoseTrianglesAllCollapseIsEmpty) {
    const GlobalGrid grid = TestGrid(1.0);
    BrickMesh mesh;
    mesh.positions = {{0, 0, 0}, {0.01f, 0, 0}, {0, 0.01f, 0}};
    mesh.indices = {0, 1, 2};
    mesh.material_ids = {0};
    auto encoded = EncodeBrick(mesh, Bounds3f({0, 0, 0}, {1, 1, 1}), grid, {});
    ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
    EXPECT_EQ(encoded->triangle_count, 0u);
    EXPECT_EQ(encoded->dropped_triangle_count, 1u);
    auto decoded = codec::DecodeMeshSection(encoded->mesh_bytes, grid, 1, "test");
    ASSERT_TRUE(decoded.ok());
    EXPECT_EQ(decoded->TriangleCount(), 0u);
}

TEST(StoreRoundTrip, ConcurrentReadsGiveIdenticalBricks) {
    ScratchDir dir;
    const BrickMesh mesh = testing::MakeSurface({.quads_x = 24, .quads_y = 24});
    auto written = testing::WriteGridStore(dir / "s.nave", mesh, testing::MakeMaterials(3),
                                           {2, 2, 1}, TestGrid());
    ASSERT_TRUE(written.ok()) << written.status().ToString();
    auto store = Store::Open(dir / "s.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    const uint32_t n = uint32_t((*store)->bricks().size());
    std::vector<std::vector<BrickMesh>> results(4, std::vector<BrickMesh>(n));
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            for (uint32_t i = 0; i < 3 * n; ++i) {
                const uint32_t b = (i + uint32_t(t)) % n;
                auto read = (*store)->ReadBrick(b);
                if (read.ok()) results[t][b] = std::move(read).value();
            }
        });
    }
    for (auto& th : threads) th.join();
    for (uint32_t b = 0; b < n; ++b) {
        for (int t = 1; t < 4; ++t) {
            EXPECT_EQ(results[t][b].positions, results[0][b].positions);
            EXPECT_EQ(results[t][b].indices, results[0][b].indices);
            EXPECT_EQ(results[t][b].material_ids, results[0][b].material_ids);
        }
        EXPECT_EQ(results[0][b].TriangleCount(), (*store)->bricks()[b].triangle_count);
    }
}

TEST(StoreRoundTrip, SideSectionIsVerifiedAndRoundTrips) {
    const std::string raw = "original triangle ids would go here " + std::string(1000, 'x');
    const std::string packed = codec::CompressSideSection(raw);
    EXPECT_LT(packed.size(), raw.size());
    auto unpacked = codec::DecompressSideSection(packed, "test");
    ASSERT_TRUE(unpacked.ok()) << unpacked.status().ToString();
    EXPECT_EQ(*unpacked, raw);

    // A store whose brick carries a side section opens, reads and verifies.
    ScratchDir dir;
    const GlobalGrid grid = TestGrid();
    const BrickMesh mesh = testing::MakeSurface({.quads_x = 4, .quads_y = 4});
    testing::GridStore split = testing::SplitOnGrid(mesh, {1, 1, 1});
    auto writer = StoreWriter::Create(dir / "side.nave", grid, {});
    ASSERT_TRUE(writer.ok());
    auto encoded = EncodeBrick(split.bricks[0], {}, grid, {});
    ASSERT_TRUE(encoded.ok());
    encoded->side_bytes = packed;
    ASSERT_TRUE((*writer)->Append(*encoded).ok());
    ASSERT_TRUE(
        (*writer)->Finish(testing::MakeMaterials(3), split.tree, mesh.TriangleCount()).ok());
    auto store = Store::Open(dir / "side.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->bricks()[0].side.length, packed.size());
    EXPECT_EQ((*store)->bricks()[0].cell, split.tree.BrickCells(1)[0]);  // taken from the tree
    EXPECT_TRUE((*store)->VerifyBrick(0).ok());
}

TEST(StoreWriter, RefusesBadMeshes) {
    const GlobalGrid grid = TestGrid();
    BrickMesh mesh = testing::MakeSurface({.quads_x = 2, .quads_y = 2});
    BrickMesh bad = mesh;
    bad.indices[4] = 99;
    Status s = EncodeBrick(bad, {}, grid, {}).status();
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find("triangle 1 corner 1: index 99 out of range [0, 9)"),
              std::string::npos)
        << s.message();

    bad = mesh;
    bad.material_ids.pop_back();
    EXPECT_EQ(EncodeBrick(bad, {}, grid, {}).status().code(), StatusCode::kInvalidArgument);

    bad = mesh;
    bad.normals[3] = {0, 0, 0};
    s = EncodeBrick(bad, {}, grid, {}).status();
    EXPECT_NE(s.message().find("vertex 3: normal"), std::string::npos) << s.message();

    bad = mesh;
    bad.positions[2] = {1e9f, 0, 0};  // 1e12 grid steps: beyond int32
    s = EncodeBrick(bad, {}, grid, {}).status();
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find("vertex 2"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("int32 range"), std::string::npos) << s.message();

    EXPECT_EQ(ValidateBrickMesh(mesh, 1).code(),
              StatusCode::kInvalidArgument);  // material 1 and 2 >= 1
    EXPECT_TRUE(ValidateBrickMesh(mesh, 3).ok());
}

TEST(StoreWriter, FinishRefusesInconsistentTablesAndCanRetry) {
    ScratchDir dir;
    const GlobalGrid grid = TestGrid();
    const BrickMesh mesh = testing::MakeSurface({.quads_x = 6, .quads_y = 6});
    testing::GridStore split = testing::SplitOnGrid(mesh, {2, 1, 1});
    auto writer = StoreWriter::Create(dir / "w.nave", grid, {});
    ASSERT_TRUE(writer.ok());
    for (const BrickMesh& b : split.bricks) {
        auto e = EncodeBrick(b, {}, grid, {});
        ASSERT_TRUE(e.ok());
        ASSERT_TRUE((*writer)->Append(*e).ok());
    }
    // Too few materials for the ids in use.
    Status s = (*writer)->Finish(testing::MakeMaterials(1), split.tree, 0);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find("uses material"), std::string::npos) << s.message();
    // Duplicate material names.
    auto twice = testing::MakeMaterials(3);
    twice[2].name = twice[0].name;
    s = (*writer)->Finish(twice, split.tree, 0);
    EXPECT_NE(s.message().find("used twice"), std::string::npos) << s.message();
    // A tree that forgets brick 1.
    std::vector<BrickTreeNode> one_leaf(1);
    one_leaf[0].brick = 0;
    s = (*writer)->Finish(testing::MakeMaterials(3), BrickTree(split.tree.bounds(), one_leaf), 0);
    EXPECT_NE(s.message().find("brick 1 is in no leaf"), std::string::npos) << s.message();
    EXPECT_FALSE(std::filesystem::exists(dir / "w.nave"));
    // Fixed: it commits.
    ASSERT_TRUE(
        (*writer)->Finish(testing::MakeMaterials(3), split.tree, mesh.TriangleCount()).ok());
    EXPECT_TRUE(Store::Open(dir / "w.nave").ok());
}

}  // namespace
}  // namespace nave::store

namespace nave::store {
namespace {

// Format 1.1 appended alpha_cutoff to each material record; a 1.0 record ends before it and must
// read as the default, while a 1.1 record keeps its value.
TEST(StoreMaterialTable, ReadsRecordsOfFormat10WithoutAlphaCutoff) {
    using format::DecodeMaterials;
    using format::EncodeMaterials;
    using format::RawHeader;
    std::vector<MaterialRecord> materials = testing::MakeMaterials(2);
    materials[0].alpha_cutoff = 0.25f;
    materials[1].alpha_cutoff = 0.75f;
    const std::string v11 = EncodeMaterials(materials);
    RawHeader h;
    h.material_count = 2;
    auto back = DecodeMaterials(v11, h, "t.nave");
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ((*back)[0].alpha_cutoff, 0.25f);
    EXPECT_EQ((*back)[1].alpha_cutoff, 0.75f);

    // Rebuild the table as 1.0 wrote it: each record 4 bytes shorter, its length field to match.
    std::string v10;
    for (size_t pos = 0; pos < v11.size();) {
        uint32_t length = 0;
        std::memcpy(&length, v11.data() + pos, 4);
        const uint32_t shorter = length - 4;
        v10.append(reinterpret_cast<const char*>(&shorter), 4);
        v10.append(v11, pos + 4, shorter);
        pos += 4 + length;
    }
    ASSERT_EQ(v10.size() + 8, v11.size());
    auto old = DecodeMaterials(v10, h, "t.nave");
    ASSERT_TRUE(old.ok()) << old.status().ToString();
    EXPECT_EQ((*old)[0].alpha_cutoff, 0.5f);
    EXPECT_EQ((*old)[1].name, materials[1].name);
    EXPECT_EQ((*old)[1].textures, materials[1].textures);
}

}  // namespace
}  // namespace nave::store
