// Derived normals in format 3.0 mesh sections (store/face_shading.h): smooth faces whose normals
// can be recomputed from the decoded positions store none; creases stay sharp; faces near a
// brick's cell boundary keep theirs; stores of format 2.0 still read.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "store/brick_codec.h"
#include "store/face_shading.h"
#include "store/store_reader.h"
#include "store/testing/store_testing.h"
#include "test_util.h"

namespace nave::store {
namespace {

constexpr uint32_t kMaterials = 2;
const GlobalGrid kGrid{{-2.0, -2.0, -1.0}, 1e-4};

/// The chord between two unit vectors `degrees` apart, plus float rounding.
double ChordBound(double degrees) { return 2 * std::sin(degrees * M_PI / 360) + 1e-5; }
/// Ten-bit octahedral normals (the stored ones) err by at most this much (round_trip_test.cpp).
const double kStoredBound = 2.0 / ((1 << 10) - 1) * std::sqrt(4.5);

/// A column: a cylinder of radius 0.5 and height 1 with smooth radial normals, under a frustum (a
/// cone to radius 0.3 at height 1.4) whose normals tilt up. The two meet in a crease at z = 1,
/// where the input splits its vertices, as modelling tools and the abbey generator do.
BrickMesh Column(int around) {
    BrickMesh m;
    auto ring = [&](double radius, double z, double nr, double nz) {
        const uint32_t first = uint32_t(m.positions.size());
        for (int i = 0; i < around; ++i) {
            const double a = 2 * M_PI * i / around;
            m.positions.emplace_back(float(radius * std::cos(a)), float(radius * std::sin(a)),
                                     float(z));
            m.normals.emplace_back(float(nr * std::cos(a)), float(nr * std::sin(a)), float(nz));
        }
        return first;
    };
    auto strip = [&](uint32_t lower, uint32_t upper, uint32_t material) {
        for (int i = 0; i < around; ++i) {
            const uint32_t j = uint32_t((i + 1) % around);
            // Counter-clockwise seen from outside.
            m.indices.insert(m.indices.end(), {lower + i, lower + j, upper + j});
            m.indices.insert(m.indices.end(), {lower + i, upper + j, upper + i});
            m.material_ids.insert(m.material_ids.end(), {material, material});
        }
    };
    // Cylinder: rows at z = 0, 0.25, ..., 1.
    uint32_t below = ring(0.5, 0.0, 1, 0);
    for (int row = 1; row <= 4; ++row) {
        const uint32_t above = ring(0.5, 0.25 * row, 1, 0);
        strip(below, above, 0);
        below = above;
    }
    // Frustum: its own vertices on the crease ring, then two rows up.
    const double slope = std::atan2(0.2, 0.4);  // radius shrinks 0.2 over 0.4
    const double nr = std::cos(slope), nz = std::sin(slope);
    below = ring(0.5, 1.0, nr, nz);
    for (int row = 1; row <= 2; ++row) {
        const uint32_t above = ring(0.5 - 0.1 * row, 1.0 + 0.2 * row, nr, nz);
        strip(below, above, 0);
        below = above;
    }
    return m;
}

/// For each decoded triangle, the input triangle on the same grid points, its corners aligned:
/// out[t][c] is the input vertex at decoded corner c of triangle t.
std::vector<std::array<uint32_t, 3>> MatchCorners(const BrickMesh& in, const BrickMesh& out) {
    std::map<std::array<std::array<int32_t, 3>, 3>, std::array<uint32_t, 3>> by_corners;
    for (size_t t = 0; t < in.TriangleCount(); ++t) {
        std::array<std::array<int32_t, 3>, 3> key;
        std::array<uint32_t, 3> vertex;
        for (int c = 0; c < 3; ++c) {
            vertex[c] = in.indices[3 * t + c];
            key[c] = test::GridKey(kGrid, in.positions[vertex[c]]);
        }
        const int first = int(std::min_element(key.begin(), key.end()) - key.begin());
        std::rotate(key.begin(), key.begin() + first, key.end());
        std::rotate(vertex.begin(), vertex.begin() + first, vertex.end());
        by_corners[key] = vertex;
    }
    std::vector<std::array<uint32_t, 3>> match(out.TriangleCount());
    for (size_t t = 0; t < out.TriangleCount(); ++t) {
        std::array<std::array<int32_t, 3>, 3> key;
        for (int c = 0; c < 3; ++c)
            key[c] = test::GridKey(kGrid, out.positions[out.indices[3 * t + c]]);
        // Decoding starts every triangle at its lowest grid point already.
        auto it = by_corners.find(key);
        EXPECT_NE(it, by_corners.end()) << "decoded triangle " << t << " is not in the input";
        if (it != by_corners.end()) match[t] = it->second;
    }
    return match;
}

StatusOr<BrickMesh> RoundTrip(const BrickMesh& mesh, const EncodeOptions& options,
                              codec::EncodedMesh* encoded,
                              const Bounds3f& complete_within = Bounds3f(Vec3f(-9, -9, -9),
                                                                         Vec3f(9, 9, 9))) {
    NAVE_ASSIGN_OR_RETURN(*encoded,
                          codec::EncodeMeshSection(mesh, kGrid, options, complete_within));
    return codec::DecodeMeshSection(encoded->bytes, kGrid, kMaterials, "test brick");
}

TEST(DerivedNormals, SmoothFacesStoreNoNormalsAndDecodeWithinTheError) {
    const BrickMesh in = Column(64);
    const EncodeOptions options;
    codec::EncodedMesh derived, stored;
    auto out = RoundTrip(in, options, &derived);
    ASSERT_TRUE(out.ok()) << out.status().ToString();
    EncodeOptions keep = options;
    keep.derived_normal_error_deg = 0;
    auto kept = RoundTrip(in, keep, &stored);
    ASSERT_TRUE(kept.ok()) << kept.status().ToString();

    uint32_t flags = 0;
    std::memcpy(&flags, derived.bytes.data() + 12, 4);
    EXPECT_EQ(flags, codec::kMeshFlagShading);
    EXPECT_TRUE(derived.has_normals);
    ASSERT_TRUE(out->HasNormals());
    ASSERT_EQ(out->TriangleCount(), in.TriangleCount());
    // Without normals to tell them apart the column's corners join by grid point, except along
    // the crease (two smoothing groups) and where Draco splits the open rims.
    EXPECT_LT(derived.bytes.size(), stored.bytes.size() * 0.8)
        << "derived " << derived.bytes.size() << " bytes, stored " << stored.bytes.size();

    const auto match = MatchCorners(in, *out);
    double worst = 0;
    for (size_t t = 0; t < out->TriangleCount(); ++t) {
        for (int c = 0; c < 3; ++c) {
            const Vec3f n = out->normals[out->indices[3 * t + c]];
            const Vec3f given = Normalize(in.normals[match[t][c]]);
            EXPECT_NEAR(Length(n), 1.f, 1e-5f) << "triangle " << t;
            worst = std::max(worst, double(Length(n - given)));
        }
    }
    // Both sides of the crease keep their own normals: the cylinder's are horizontal at z = 1,
    // the frustum's tilt up by 26.6 degrees; averaging them would err by 13 degrees.
    EXPECT_LE(worst, ChordBound(options.derived_normal_error_deg));
    EXPECT_GT(worst, 0) << "normals equal to the float bit cannot have been recomputed";
}

TEST(DerivedNormals, FacesTouchingTheCellBoundaryKeepStoredNormals) {
    // Only the half x < 0 holds whole fans: faces with a corner near or beyond x = 0 may be cut
    // by the brick boundary, so they keep the stored normals, exactly as with derivation off.
    const BrickMesh in = Column(64);
    const EncodeOptions options;
    EncodeOptions keep = options;
    keep.derived_normal_error_deg = 0;
    codec::EncodedMesh half_encoded, whole_encoded, stored_encoded;
    auto half = RoundTrip(in, options, &half_encoded, Bounds3f(Vec3f(-9, -9, -9), Vec3f(0, 9, 9)));
    auto whole = RoundTrip(in, options, &whole_encoded);
    auto stored = RoundTrip(in, keep, &stored_encoded);
    ASSERT_TRUE(half.ok() && whole.ok() && stored.ok());
    EXPECT_LT(whole_encoded.bytes.size(), half_encoded.bytes.size());
    EXPECT_LT(half_encoded.bytes.size(), stored_encoded.bytes.size());

    // Stored normals by the input vertex they came from (decoding is deterministic).
    const auto stored_match = MatchCorners(in, *stored);
    std::map<uint32_t, Vec3f> stored_normal;
    for (size_t t = 0; t < stored->TriangleCount(); ++t) {
        for (int c = 0; c < 3; ++c)
            stored_normal[stored_match[t][c]] = stored->normals[stored->indices[3 * t + c]];
    }
    const auto match = MatchCorners(in, *half);
    size_t right_faces = 0;
    for (size_t t = 0; t < half->TriangleCount(); ++t) {
        bool right = true;
        for (int c = 0; c < 3; ++c) right &= in.positions[match[t][c]].x > 0.01f;
        if (!right) continue;
        ++right_faces;
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(half->normals[half->indices[3 * t + c]], stored_normal[match[t][c]])
                << "triangle " << t << " corner " << c << " beyond the cell was not stored";
        }
    }
    EXPECT_GT(right_faces, in.TriangleCount() / 3);
}

TEST(DerivedNormals, NormalsThePositionsDoNotExplainAreStored) {
    // Normals that the positions do not explain (a bump map baked into them) cannot be derived.
    BrickMesh in = Column(64);
    for (size_t v = 0; v < in.normals.size(); ++v) {
        const float wobble = 0.2f * float(std::sin(double(v) * 12.9898) * 0.5);
        in.normals[v] = Normalize(in.normals[v] + Vec3f(0, 0, wobble));
    }
    codec::EncodedMesh encoded;
    auto out = RoundTrip(in, EncodeOptions(), &encoded);
    ASSERT_TRUE(out.ok()) << out.status().ToString();
    const auto match = MatchCorners(in, *out);
    for (size_t t = 0; t < out->TriangleCount(); ++t) {
        for (int c = 0; c < 3; ++c) {
            const Vec3f n = out->normals[out->indices[3 * t + c]];
            EXPECT_LE(Length(n - Normalize(in.normals[match[t][c]])),
                      ChordBound(EncodeOptions().derived_normal_error_deg))
                << "triangle " << t;
        }
    }
}

TEST(DerivedNormals, OutOfRangeErrorIsRefused) {
    EncodeOptions options;
    options.derived_normal_error_deg = -1;
    auto e = codec::EncodeMeshSection(Column(8), kGrid, options);
    ASSERT_FALSE(e.ok());
    EXPECT_EQ(e.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(e.status().message().find("derived normal error -1"), std::string::npos)
        << e.status().message();
}

TEST(DerivedNormals, BothShadingFlagsAreRefused) {
    auto e = codec::EncodeMeshSection(Column(16), kGrid, EncodeOptions());
    ASSERT_TRUE(e.ok());
    std::string bytes = e->bytes;
    const uint32_t flags = codec::kMeshFlagFlatFaces | codec::kMeshFlagShading;
    std::memcpy(bytes.data() + 12, &flags, 4);
    auto out = codec::DecodeMeshSection(bytes, kGrid, kMaterials, "abbey.nave brick 3");
    ASSERT_FALSE(out.ok());
    EXPECT_EQ(out.status().code(), StatusCode::kDataLoss);
    EXPECT_NE(out.status().message().find("abbey.nave brick 3"), std::string::npos);
    EXPECT_NE(out.status().message().find("0x3"), std::string::npos) << out.status().message();
}

// tests/fixtures/stores/cylinder_on_box_v2_0.nave was written by nave's format 2.0 writer from
// tests/fixtures/models/cylinder_on_box.obj: a smooth cylinder (normals stored) on a faceted box.
TEST(DerivedNormals, Format20StoresStillRead) {
    auto store = Store::Open(std::string(NAVE_TEST_FIXTURES) + "/stores/cylinder_on_box_v2_0.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->header().major, 2);
    EXPECT_EQ((*store)->header().minor, 0);
    ASSERT_EQ((*store)->bricks().size(), 1u);
    EXPECT_TRUE((*store)->VerifyBrick(0).ok());
    auto mesh = (*store)->ReadBrick(0);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    ASSERT_EQ(mesh->TriangleCount(), 156u);  // 24 x 3 x 2 on the cylinder, 12 on the box
    ASSERT_TRUE(mesh->HasNormals());
    size_t flat = 0;
    for (size_t t = 0; t < mesh->TriangleCount(); ++t) {
        const Vec3f n = mesh->normals[mesh->indices[3 * t]];
        if (Length(n) == 0.f) {
            ++flat;
            continue;
        }
        // The cylinder's normals are horizontal and radial.
        const Vec3f p = mesh->positions[mesh->indices[3 * t]];
        EXPECT_NEAR(n.z, 0.f, 5e-3f) << "triangle " << t;
        EXPECT_NEAR(Dot(n, Normalize(Vec3f(p.x, p.y, 0))), 1.f, 1e-3f) << "triangle " << t;
    }
    EXPECT_EQ(flat, 12u);
}

}  // namespace
}  // namespace nave::store
