// Levels of detail in the store (format 3.1, on coarser grids in 3.2): written and read back with
// their counts, errors and sections; stores without levels (3.0 and older, or written without) open
// with none; damage to a level's mesh section or to the levels table is refused naming the brick
// and the level.

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "src/core/file.h"
#include "src/core/hash.h"
#include "store/brick_codec.h"
#include "store/store_format.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "store/testing/store_testing.h"
#include "test_util.h"

namespace nave::store {
namespace {

using test::ScratchDir;

std::string Hex(uint64_t v) { return fmt::format("0x{:x}", v); }

void ExpectError(const Status& status, StatusCode code, std::initializer_list<std::string> parts) {
    EXPECT_EQ(status.code(), code) << status.ToString();
    for (const std::string& p : parts)
        EXPECT_NE(status.message().find(p), std::string::npos)
            << status.message() << "\n  lacks: " << p;
}

/// Two levels on every brick of the test surface: errors of 0.2 % and 5 % of a brick's extent,
/// borders free (these tests are about the format; locked borders would stop the second level).
LevelOptions TwoLevels() {
    LevelOptions l;
    l.relative_errors = {0.002, 0.05};
    l.border_lock = LevelOptions::BorderLock::kNone;
    return l;
}

EncodeOptions WithLevels() {
    EncodeOptions o;
    o.levels = TwoLevels();
    return o;
}

// A 48 x 48-quad surface cut into 2 x 2 bricks of about 1150 triangles each, with two levels each.
class StoreLevels : public ::testing::Test {
  protected:
    void SetUp() override {
        mesh_ = testing::MakeSurface({.quads_x = 48, .quads_y = 48});
        auto written = testing::WriteGridStore(good_, mesh_, testing::MakeMaterials(3), {2, 2, 1},
                                               grid_, WithLevels());
        ASSERT_TRUE(written.ok()) << written.status().ToString();
        split_ = std::move(*written);
        auto bytes = ReadFileToString(good_);
        ASSERT_TRUE(bytes.ok());
        bytes_ = *bytes;
        auto header = format::DecodeHeader(bytes_, "x", bytes_.size());
        ASSERT_TRUE(header.ok()) << header.status().ToString();
        header_ = *header;
    }

    StatusOr<std::unique_ptr<Store>> OpenBytes(const std::string& bytes) {
        return test::OpenStoreBytes(bad_, bytes);
    }
    // `bytes` with the levels table's checksum and the header's recomputed (a writer's bug behind
    // valid checksums).
    std::string Resealed(std::string bytes) const {
        format::RawHeader h = header_;
        h.levels.checksum = Checksum64(bytes.data() + h.levels.offset, h.levels.length);
        const std::string header = format::EncodeHeader(h);
        return bytes.replace(0, header.size(), header);
    }
    // Offset in the file of brick `id`'s level `k` entry in the levels table.
    uint64_t LevelEntryOffset(uint32_t id, uint32_t k) const {
        uint64_t at = header_.levels.offset + format::kLevelsPrefixBytes;
        for (uint32_t b = 0; b < id; ++b) {
            uint32_t count = 0;
            std::memcpy(&count, &bytes_[at], 4);
            at += 4 + uint64_t(count) * format::kLevelEntryBytes;
        }
        return at + 4 + uint64_t(k - 1) * format::kLevelEntryBytes;
    }

    ScratchDir dir_;
    std::filesystem::path good_ = dir_ / "good.nave";
    std::filesystem::path bad_ = dir_ / "bad.nave";
    GlobalGrid grid_{{0, 0, 0}, 1e-3};
    BrickMesh mesh_;
    testing::GridStore split_;
    std::string bytes_;
    format::RawHeader header_;
};

TEST_F(StoreLevels, RoundTripKeepsCountsErrorsAndSections) {
    auto opened = Store::Open(good_);
    ASSERT_TRUE(opened.ok()) << opened.status().ToString();
    const Store& store = **opened;
    EXPECT_EQ(store.header().major, 3);
    EXPECT_EQ(store.header().minor, kFormatMinor);
    ASSERT_EQ(store.bricks().size(), 4u);
    for (const BrickInfo& b : store.bricks()) {
        SCOPED_TRACE(::testing::Message() << "brick " << b.id);
        // The table holds what EncodeBrick made.
        auto encoded =
            EncodeBrick(split_.bricks[b.id], store.tree().BrickCells(4)[b.id], grid_, WithLevels());
        ASSERT_TRUE(encoded.ok());
        ASSERT_EQ(b.levels.size(), 2u);
        ASSERT_EQ(encoded->levels.size(), 2u);
        uint64_t end = b.mesh.offset + b.mesh.length;
        for (uint32_t k = 1; k <= 2; ++k) {
            const LevelInfo& l = b.levels[k - 1];
            const EncodedLevel& e = encoded->levels[k - 1];
            EXPECT_EQ(l.error, e.error);
            EXPECT_EQ(l.triangle_count, e.triangle_count);
            EXPECT_EQ(l.vertex_count, e.vertex_count);
            EXPECT_EQ(l.decoded_bytes, e.decoded_bytes);
            EXPECT_FALSE(l.has_normals);  // levels are shaded with their facets' normals
            EXPECT_TRUE(l.has_uvs);
            EXPECT_GT(l.error, k == 1 ? 0.f : b.levels[0].error);
            EXPECT_LT(l.triangle_count, k == 1 ? b.triangle_count : b.levels[0].triangle_count);
            // Each level's section follows the brick's (or the level before it).
            EXPECT_EQ(l.mesh.offset, end);
            EXPECT_EQ(l.mesh.length, e.mesh_bytes.size());
            EXPECT_EQ(bytes_.substr(l.mesh.offset, l.mesh.length), e.mesh_bytes);
            end = l.mesh.offset + l.mesh.length;

            const uint64_t before = store.bytes_read();
            auto mesh = store.ReadBrick(b.id, k);
            ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
            EXPECT_EQ(store.bytes_read() - before, l.mesh.length);
            EXPECT_EQ(mesh->TriangleCount(), l.triangle_count);
            EXPECT_EQ(mesh->VertexCount(), l.vertex_count);
            EXPECT_EQ(mesh->MemoryBytes(), l.decoded_bytes);
            // Decoded, like the brick itself: flat faces carry zero normals (brick_mesh.h), so
            // ValidateBrickMesh (for meshes handed to the writer) does not apply; ids and indices
            // do.
            for (uint32_t m : mesh->material_ids) EXPECT_LT(m, 3u);
            for (uint32_t i : mesh->indices) EXPECT_LT(i, mesh->VertexCount());
        }
        EXPECT_TRUE(store.VerifyBrick(b.id).ok()) << store.VerifyBrick(b.id).ToString();
        auto full = store.ReadBrick(b.id, 0);
        ASSERT_TRUE(full.ok());
        EXPECT_EQ(full->TriangleCount(), b.triangle_count);
    }
}

// A level snaps to every 2^s-th point of the store's grid (s from its error, as the mesh section's
// prefix records), which adds the snapping distance to its error and takes fewer bytes than the
// store's own grid would.
TEST_F(StoreLevels, LevelsSnapToACoarserGridWithinTheirError) {
    auto opened = Store::Open(good_);
    ASSERT_TRUE(opened.ok()) << opened.status().ToString();
    const Store& store = **opened;
    EncodeOptions fine = WithLevels();
    fine.levels.max_grid_error_fraction = 0;
    int shifted = 0;
    for (const BrickInfo& b : store.bricks()) {
        auto on_fine =
            EncodeBrick(split_.bricks[b.id], store.tree().BrickCells(4)[b.id], grid_, fine);
        ASSERT_TRUE(on_fine.ok()) << on_fine.status().ToString();
        ASSERT_EQ(on_fine->levels.size(), b.levels.size());
        for (uint32_t k = 1; k <= b.levels.size(); ++k) {
            SCOPED_TRACE(::testing::Message() << "brick " << b.id << " level " << k);
            const LevelInfo& l = b.levels[k - 1];
            uint32_t flags = 0;
            std::memcpy(&flags, &bytes_[l.mesh.offset + 12], 4);
            const uint32_t shift = (flags & codec::kMeshGridShiftMask) >> codec::kMeshGridShiftBit;
            const EncodedLevel& f = on_fine->levels[k - 1];
            if (shift == 0) {
                EXPECT_EQ(l.mesh.length, f.mesh_bytes.size());
                continue;
            }
            ++shifted;
            // Within the fraction of the error the options allow, and counted in it.
            const double snap = GridSnapDistance(grid_, shift);
            EXPECT_LE(snap, TwoLevels().max_grid_error_fraction * f.error);
            EXPECT_NEAR(l.error, f.error + snap, 1e-6 * (f.error + snap));
            EXPECT_LT(l.mesh.length, f.mesh_bytes.size());
            auto mesh = store.ReadBrick(b.id, k);
            ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
            const double spacing = grid_.step * double(1u << shift);
            for (const Vec3f& p : mesh->positions) {
                for (int a = 0; a < 3; ++a) {
                    const double cells = (double(p[a]) - grid_.origin[a]) / spacing;
                    ASSERT_NEAR(cells, std::round(cells), 1e-3) << "axis " << a;
                }
            }
        }
    }
    EXPECT_GT(shifted, 0);
}

// A grid shift past the largest the format allows is damage, named with the section.
TEST(LevelGridShift, SectionsWithAnImpossibleShiftAreRefused) {
    const BrickMesh mesh = testing::MakeSurface({.quads_x = 8, .quads_y = 8});
    const GlobalGrid grid{{0, 0, 0}, 1e-3};
    const Bounds3f kEverywhere(Vec3f(-codec::kInfinity, -codec::kInfinity, -codec::kInfinity),
                               Vec3f(codec::kInfinity, codec::kInfinity, codec::kInfinity));
    auto encoded = codec::EncodeMeshSection(mesh, grid, EncodeOptions(), kEverywhere, 3);
    ASSERT_TRUE(encoded.ok()) << encoded.status().ToString();
    auto decoded = codec::DecodeMeshSection(encoded->bytes, grid, 3, "test level");
    ASSERT_TRUE(decoded.ok()) << decoded.status().ToString();
    std::string bytes = encoded->bytes;
    uint32_t flags = 0;
    std::memcpy(&flags, &bytes[12], 4);
    flags = (flags & ~codec::kMeshGridShiftMask) | (31u << codec::kMeshGridShiftBit);
    std::memcpy(&bytes[12], &flags, 4);
    ExpectError(codec::DecodeMeshSection(bytes, grid, 3, "test level").status(),
                StatusCode::kDataLoss, {"test level", "grid shift 31", "[0, 16]"});
    EXPECT_EQ(
        codec::EncodeMeshSection(mesh, grid, EncodeOptions(), kEverywhere, 17).status().code(),
        StatusCode::kInvalidArgument);
}

TEST_F(StoreLevels, LevelPastTheLastIsNotFoundNamingIt) {
    auto store = Store::Open(good_);
    ASSERT_TRUE(store.ok());
    ExpectError((*store)->ReadBrick(1, 3).status(), StatusCode::kNotFound,
                {good_.string(), "brick 1 has no level 3", "levels are 0 to 2"});
    ExpectError((*store)->ReadBrick(9, 1).status(), StatusCode::kNotFound, {"brick 9"});
}

TEST_F(StoreLevels, StoresWithoutLevelsOpenWithNone) {
    // Written without levels: no levels table.
    const std::filesystem::path plain = dir_ / "plain.nave";
    ASSERT_TRUE(
        testing::WriteGridStore(plain, mesh_, testing::MakeMaterials(3), {2, 2, 1}, grid_).ok());
    auto store = Store::Open(plain);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    for (const BrickInfo& b : (*store)->bricks()) {
        EXPECT_TRUE(b.levels.empty());
        EXPECT_TRUE((*store)->VerifyBrick(b.id).ok());
        ExpectError((*store)->ReadBrick(b.id, 1).status(), StatusCode::kNotFound,
                    {"has no level 1", "levels are 0 to 0"});
    }
    // A 3.0 store: its header has zeros where 3.1 points at the levels table.
    const std::string bytes = ReadFileToString(plain).value();
    format::RawHeader h = format::DecodeHeader(bytes, "plain", bytes.size()).value();
    EXPECT_EQ(h.levels.length, 0u);
    h.minor = 0;
    std::string old = bytes;
    const std::string header = format::EncodeHeader(h);
    old.replace(0, header.size(), header);
    store = OpenBytes(old);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->header().minor, 0);
    for (const BrickInfo& b : (*store)->bricks()) EXPECT_TRUE(b.levels.empty());
}

TEST_F(StoreLevels, FlippedLevelByteIsReportedWithBrickLevelAndOffset) {
    auto good = Store::Open(good_);
    ASSERT_TRUE(good.ok());
    const LevelInfo& l = (*good)->bricks()[2].levels[1];
    std::string bytes = bytes_;
    bytes[l.mesh.offset + l.mesh.length / 2] ^= 0x5a;
    auto store = OpenBytes(bytes);
    ASSERT_TRUE(store.ok()) << "Open reads no level payload: " << store.status().ToString();
    EXPECT_TRUE((*store)->ReadBrick(2, 0).ok());
    EXPECT_TRUE((*store)->ReadBrick(2, 1).ok());
    const Status s = (*store)->ReadBrick(2, 2).status();
    ExpectError(s, StatusCode::kDataLoss,
                {bad_.string() + " brick 2 @" + Hex(l.mesh.offset) + ": level 2 mesh checksum",
                 "!= stored " + ChecksumHex(l.mesh.checksum)});
    ExpectError((*store)->VerifyBrick(2), StatusCode::kDataLoss, {"brick 2", "level 2"});
    for (uint32_t id : {0u, 1u, 3u}) EXPECT_TRUE((*store)->VerifyBrick(id).ok());
}

TEST_F(StoreLevels, FlippedLevelsTableByteIsRefusedAtOpen) {
    for (uint64_t at : {header_.levels.offset, header_.levels.offset + header_.levels.length / 2,
                        header_.levels.offset + header_.levels.length - 1}) {
        std::string bytes = bytes_;
        bytes[at] ^= 0x5a;
        auto store = OpenBytes(bytes);
        ExpectError(store.status(), StatusCode::kDataLoss,
                    {bad_.string(), "levels table @" + Hex(header_.levels.offset) + ": checksum"});
    }
}

TEST_F(StoreLevels, InconsistentLevelsBehindValidChecksumsAreRefused) {
    const uint64_t entry = LevelEntryOffset(1, 2);
    {
        // Level 2's error no larger than level 1's.
        std::string bytes = bytes_;
        const float zero = 0;
        std::memcpy(&bytes[entry], &zero, 4);
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {bad_.string() + " brick 1 level 2 @" + Hex(entry), "error 0",
                     "larger than level 1's"});
    }
    {
        // Level 2's mesh section past the payloads.
        std::string bytes = bytes_;
        const uint64_t past_end = header_.materials.offset;
        std::memcpy(&bytes[entry + 32], &past_end, 8);
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {bad_.string() + " brick 1 level 2 @" + Hex(entry), "mesh section",
                     "outside the payload area"});
    }
    {
        // More triangles than the brick itself.
        std::string bytes = bytes_;
        const uint64_t many = 1u << 30;
        std::memcpy(&bytes[LevelEntryOffset(1, 1) + 8], &many, 8);
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {"brick 1 level 1", "1073741824 triangles"});
    }
    {
        // A level count no table could hold.
        std::string bytes = bytes_;
        const uint32_t count = 1000;
        std::memcpy(&bytes[LevelEntryOffset(1, 1) - 4], &count, 4);
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {"brick 1 levels", "1000 levels"});
    }
    {
        // A level's triangle count that the decoded mesh does not have (decoded bytes kept
        // consistent): Open accepts the table, reading the level refuses it.
        std::string bytes = bytes_;
        const uint64_t at = LevelEntryOffset(3, 1);
        uint64_t triangles = 0, vertices = 0;
        std::memcpy(&triangles, &bytes[at + 8], 8);
        std::memcpy(&vertices, &bytes[at + 16], 8);
        triangles -= 1;
        const uint64_t decoded =
            BrickMesh::BytesFor(vertices, triangles, /*has_normals=*/false, true);
        std::memcpy(&bytes[at + 8], &triangles, 8);
        std::memcpy(&bytes[at + 24], &decoded, 8);
        auto store = OpenBytes(Resealed(bytes));
        ASSERT_TRUE(store.ok()) << store.status().ToString();
        ExpectError((*store)->ReadBrick(3, 1).status(), StatusCode::kDataLoss,
                    {"brick 3 level 1", "levels table says"});
    }
}

}  // namespace
}  // namespace nave::store
