// Flat faces in format 2.0 mesh sections: faces whose normals are their geometric normal store no
// normals and share their corners; smooth faces keep theirs; stores of format 1.x still read.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "store/brick_codec.h"
#include "store/store_reader.h"
#include "store/testing/store_testing.h"

namespace nave::store {
namespace {

constexpr uint32_t kMaterials = 4;
const GlobalGrid kGrid{{-0.123, 0.456, -0.789}, 1e-3};

/// Appends an axis-aligned box of side `size` at `corner` as an input that splits every corner by
/// face (four vertices per face, each with the face's normal), as faceted CAD exports do.
void AppendFacetedBox(BrickMesh* m, Vec3f corner, float size, uint32_t material) {
    const Vec3f axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int a = 0; a < 3; ++a) {
        for (int side = 0; side < 2; ++side) {
            const Vec3f n = axes[a] * (side == 0 ? -1.f : 1.f);
            const Vec3f u = axes[(a + 1) % 3] * size, v = axes[(a + 2) % 3] * size;
            const Vec3f origin = corner + (side == 0 ? Vec3f(0, 0, 0) : axes[a] * size);
            const uint32_t first = uint32_t(m->positions.size());
            for (const Vec3f& p : {origin, origin + u, origin + u + v, origin + v}) {
                m->positions.push_back(p);
                m->normals.push_back(n);
            }
            // Counter-clockwise seen from outside: swap the diagonal order on the negative side.
            const uint32_t quad[2][3] = {{0, 1, 2}, {0, 2, 3}};
            for (const auto& tri : quad) {
                if (side == 1) {
                    m->indices.insert(m->indices.end(),
                                      {first + tri[0], first + tri[1], first + tri[2]});
                } else {
                    m->indices.insert(m->indices.end(),
                                      {first + tri[0], first + tri[2], first + tri[1]});
                }
                m->material_ids.push_back(material);
            }
        }
    }
}

BrickMesh FacetedBoxes(int count) {
    BrickMesh m;
    for (int i = 0; i < count; ++i)
        AppendFacetedBox(&m, Vec3f(0.5f * float(i), 0, 0), 0.3f, uint32_t(i % 2));
    return m;
}

StatusOr<BrickMesh> RoundTrip(const BrickMesh& mesh, codec::EncodedMesh* encoded = nullptr) {
    NAVE_ASSIGN_OR_RETURN(codec::EncodedMesh e,
                          codec::EncodeMeshSection(mesh, kGrid, EncodeOptions()));
    if (encoded != nullptr) *encoded = e;
    return codec::DecodeMeshSection(e.bytes, kGrid, kMaterials, "test brick");
}

TEST(FlatFaces, AllFlatMeshStoresNoNormalsAndSharesCorners) {
    const BrickMesh in = FacetedBoxes(5);
    ASSERT_EQ(in.VertexCount(), 5u * 24);
    codec::EncodedMesh e;
    auto out = RoundTrip(in, &e);
    ASSERT_TRUE(out.ok()) << out.status().ToString();
    EXPECT_FALSE(e.has_normals);
    EXPECT_FALSE(out->HasNormals());
    EXPECT_EQ(out->TriangleCount(), in.TriangleCount());
    // A box's faces meet at its 8 corners once the per-face normals are gone.
    EXPECT_EQ(out->VertexCount(), 5u * 8) << "flat faces' corners were not joined";
    uint32_t flags = 0;
    std::memcpy(&flags, e.bytes.data() + 12, 4);
    EXPECT_EQ(flags, 0u) << "nothing to mark when no face keeps normals";
}

TEST(FlatFaces, MixedMeshMarksFlatFacesAndKeepsSmoothNormals) {
    testing::SurfaceOptions surface;
    surface.quads_x = 12;
    surface.quads_y = 10;
    surface.uvs = false;
    BrickMesh in = testing::MakeSurface(surface);  // wavy, smooth normals
    ASSERT_TRUE(in.HasNormals());
    const size_t smooth_triangles = in.TriangleCount();
    for (uint32_t& m : in.material_ids) m = 2;
    const BrickMesh boxes = FacetedBoxes(3);
    const uint32_t offset = uint32_t(in.positions.size());
    in.positions.insert(in.positions.end(), boxes.positions.begin(), boxes.positions.end());
    in.normals.insert(in.normals.end(), boxes.normals.begin(), boxes.normals.end());
    for (uint32_t i : boxes.indices) in.indices.push_back(i + offset);
    in.material_ids.insert(in.material_ids.end(), boxes.material_ids.begin(),
                           boxes.material_ids.end());

    codec::EncodedMesh e;
    auto out = RoundTrip(in, &e);
    ASSERT_TRUE(out.ok()) << out.status().ToString();
    ASSERT_TRUE(out->HasNormals());
    uint32_t flags = 0;
    std::memcpy(&flags, e.bytes.data() + 12, 4);
    EXPECT_EQ(flags, codec::kMeshFlagShading);
    ASSERT_EQ(out->TriangleCount(), in.TriangleCount());
    size_t flat = 0, smooth = 0;
    for (size_t t = 0; t < out->TriangleCount(); ++t) {
        const uint32_t* corner = &out->indices[3 * t];
        const bool zero = Length(out->normals[corner[0]]) == 0.f;
        for (int c = 0; c < 3; ++c) {
            const float len = Length(out->normals[corner[c]]);
            if (zero) {
                EXPECT_EQ(len, 0.f) << "triangle " << t << ": a flat face's corner has a normal";
            } else {
                EXPECT_NEAR(len, 1.f, 1e-5f) << "triangle " << t;
            }
        }
        // Materials come back exactly, the flat bit removed: the surface is 2, the boxes 0 and 1.
        if (zero) {
            ++flat;
            EXPECT_LT(out->material_ids[t], 2u) << "triangle " << t;
        } else {
            ++smooth;
            EXPECT_EQ(out->material_ids[t], 2u) << "triangle " << t;
        }
    }
    EXPECT_EQ(smooth, smooth_triangles);
    EXPECT_EQ(flat, 3u * 12);
}

TEST(FlatFaces, UnknownMeshFlagsAreRefusedNamingThem) {
    auto e = codec::EncodeMeshSection(FacetedBoxes(1), kGrid, EncodeOptions());
    ASSERT_TRUE(e.ok());
    std::string bytes = e->bytes;
    const uint32_t flags = 0x6;
    std::memcpy(bytes.data() + 12, &flags, 4);
    auto out = codec::DecodeMeshSection(bytes, kGrid, kMaterials, "abbey.nave brick 7");
    ASSERT_FALSE(out.ok());
    EXPECT_EQ(out.status().code(), StatusCode::kDataLoss);
    EXPECT_NE(out.status().message().find("abbey.nave brick 7"), std::string::npos);
    EXPECT_NE(out.status().message().find("0x6"), std::string::npos) << out.status().message();
}

// tests/fixtures/stores/shapes_v1_1.nave was written by nave's format 1.1 writer from
// tests/fixtures/models/shapes_crlf.obj (a quad, a pentagon and a triangle, normals on some).
TEST(FlatFaces, Format11StoresStillRead) {
    auto store = Store::Open(std::string(NAVE_TEST_FIXTURES) + "/stores/shapes_v1_1.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->header().major, 1);
    EXPECT_EQ((*store)->header().minor, 1);
    ASSERT_EQ((*store)->bricks().size(), 1u);
    EXPECT_TRUE((*store)->VerifyBrick(0).ok());
    auto mesh = (*store)->ReadBrick(0);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    EXPECT_EQ(mesh->TriangleCount(), 6u);
    EXPECT_EQ(mesh->VertexCount(), (*store)->bricks()[0].vertex_count);
    ASSERT_TRUE(mesh->HasNormals());
    for (const Vec3f& n : mesh->normals) EXPECT_NEAR(Length(n), 1.f, 1e-5f);
}

}  // namespace
}  // namespace nave::store
