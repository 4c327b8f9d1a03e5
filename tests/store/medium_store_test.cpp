// A medium's pieces in the store (format 3.3): written and read back with their counts and bytes,
// bricks without triangles that hold only a piece, damage to a piece or to the medium table
// refused naming the brick, and stores without the table (3.2 and older, or written without a
// medium) opening with none. The pieces' content is OpenVDB's business; here they are opaque bytes.

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "src/core/file.h"
#include "src/core/hash.h"
#include "store/store_format.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "store/testing/store_testing.h"
#include "test_util.h"

namespace nave::store {
namespace {

using test::ScratchDir;

void ExpectError(const Status& status, StatusCode code, std::initializer_list<std::string> parts) {
    EXPECT_EQ(status.code(), code) << status.ToString();
    for (const std::string& p : parts)
        EXPECT_NE(status.message().find(p), std::string::npos)
            << status.message() << "\n  lacks: " << p;
}

EncodedMedium Piece(const std::string& text, uint64_t voxels, float majorant) {
    EncodedMedium m;
    m.grid_bytes.resize(text.size());
    std::memcpy(m.grid_bytes.data(), text.data(), text.size());
    m.active_voxels = voxels;
    m.max_density = majorant;
    m.decoded_bytes = 1000 + voxels;
    return m;
}

std::string Text(const std::vector<std::byte>& bytes) {
    return std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

// A surface in brick 0 (the cell below z = 1) and, above it, a cell of medium without surface:
// brick 1, of no triangles.
class StoreMedium : public ::testing::Test {
  protected:
    void SetUp() override {
        ASSERT_TRUE(Write(good_, /*with_medium=*/true).ok());
        bytes_ = ReadFileToString(good_).value();
        header_ = format::DecodeHeader(bytes_, "x", bytes_.size()).value();
    }

    Status Write(const std::filesystem::path& path, bool with_medium) {
        const BrickMesh mesh = testing::MakeSurface({.quads_x = 8, .quads_y = 8});
        const Bounds3f root(Vec3f(0, 0, -1), Vec3f(10, 10, 3));
        std::vector<BrickTreeNode> nodes(3);
        nodes[0].axis = 2;
        nodes[0].split = 1;
        nodes[0].child[0] = 1;
        nodes[0].child[1] = 2;
        nodes[1].brick = 0;
        nodes[2].brick = with_medium ? 1 : kNoBrick;
        NAVE_ASSIGN_OR_RETURN(auto writer, StoreWriter::Create(path, grid_, {}));
        NAVE_ASSIGN_OR_RETURN(EncodedBrick surface, EncodeBrick(mesh, {}, grid_, {}));
        NAVE_RETURN_IF_ERROR(writer->Append(surface).status());
        if (with_medium) {
            NAVE_RETURN_IF_ERROR(writer->Append(EmptyBrick({})).status());
            NAVE_RETURN_IF_ERROR(writer->SetMediumGrid("density"));
            NAVE_RETURN_IF_ERROR(writer->AppendMedium(0, Piece(kPiece0, 40, 2.5f)));
            NAVE_RETURN_IF_ERROR(writer->AppendMedium(1, Piece(kPiece1, 7, 0.75f)));
        }
        return writer->Finish(testing::MakeMaterials(3), BrickTree(root, nodes), 128);
    }

    StatusOr<std::unique_ptr<Store>> OpenBytes(const std::string& bytes) {
        return test::OpenStoreBytes(bad_, bytes);
    }

    // `bytes` with the medium table's checksum and the header's recomputed (a writer's bug behind
    // valid checksums).
    std::string Resealed(std::string bytes) const {
        format::RawHeader h = header_;
        h.medium.checksum = Checksum64(bytes.data() + h.medium.offset, h.medium.length);
        const std::string header = format::EncodeHeader(h);
        return bytes.replace(0, header.size(), header);
    }

    static constexpr const char* kPiece0 = "the first piece's bytes";
    static constexpr const char* kPiece1 = "the second piece, of a cell without surface";
    ScratchDir dir_;
    std::filesystem::path good_ = dir_ / "good.nave";
    std::filesystem::path bad_ = dir_ / "bad.nave";
    GlobalGrid grid_{{0, 0, -1}, 1e-3};
    std::string bytes_;
    format::RawHeader header_;
};

TEST_F(StoreMedium, RoundTripKeepsPiecesAndBricksWithoutTriangles) {
    auto opened = Store::Open(good_);
    ASSERT_TRUE(opened.ok()) << opened.status().ToString();
    const Store& store = **opened;
    EXPECT_EQ(store.header().minor, kFormatMinor);
    EXPECT_EQ(store.header().medium_grid, "density");
    ASSERT_EQ(store.bricks().size(), 2u);
    const BrickInfo& surface = store.bricks()[0];
    const BrickInfo& empty = store.bricks()[1];
    EXPECT_EQ(surface.medium.active_voxels, 40u);
    EXPECT_EQ(surface.medium.max_density, 2.5f);
    EXPECT_EQ(surface.medium.decoded_bytes, 1040u);
    EXPECT_EQ(empty.medium.active_voxels, 7u);
    EXPECT_EQ(empty.medium.max_density, 0.75f);
    EXPECT_EQ(empty.BytesOnDisk(), empty.mesh.length + std::strlen(kPiece1));
    EXPECT_EQ(empty.cell, Bounds3f(Vec3f(0, 0, 1), Vec3f(10, 10, 3)));

    const uint64_t before = store.bytes_read();
    auto piece = store.ReadBrickMedium(1);
    ASSERT_TRUE(piece.ok()) << piece.status().ToString();
    EXPECT_EQ(Text(*piece), kPiece1);
    EXPECT_EQ(store.bytes_read() - before, std::strlen(kPiece1));
    EXPECT_EQ(Text(store.ReadBrickMedium(0).value()), kPiece0);

    // The brick without triangles reads as an empty mesh; the surface's triangles are all there.
    auto mesh = store.ReadBrick(1);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    EXPECT_EQ(mesh->TriangleCount(), 0u);
    EXPECT_EQ(mesh->VertexCount(), 0u);
    EXPECT_EQ(empty.triangle_count, 0u);
    EXPECT_EQ(store.header().triangle_count, surface.triangle_count);
    for (uint32_t b = 0; b < 2; ++b) EXPECT_TRUE(store.VerifyBrick(b).ok()) << b;
    // A ray through the empty cell visits its brick.
    std::vector<uint32_t> visited;
    store.tree().Traverse(Vec3f(5, 5, 2.5f), Vec3f(0, 0, -1), 0, 10, [&](uint32_t b, float, float) {
        visited.push_back(b);
        return true;
    });
    EXPECT_EQ(visited, (std::vector<uint32_t>{1, 0}));

    ExpectError(store.ReadBrickMedium(2).status(), StatusCode::kNotFound, {"brick 2"});
}

TEST_F(StoreMedium, StoresWithoutTheTableHaveNoMedium) {
    const std::filesystem::path plain = dir_ / "plain.nave";
    ASSERT_TRUE(Write(plain, /*with_medium=*/false).ok());
    auto store = Store::Open(plain);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->header().medium_grid, "");
    EXPECT_EQ((*store)->bricks()[0].medium.grid.length, 0u);
    ExpectError((*store)->ReadBrickMedium(0).status(), StatusCode::kNotFound,
                {"brick 0 holds no piece", "the store has none"});

    // A 3.2 header has zeros where 3.3 points at the medium table; relabelled 3.2, a store with a
    // medium opens as a 3.2 reader opens it: bricks and all, without the medium.
    format::RawHeader h = header_;
    h.minor = 2;
    std::string old = bytes_;
    const std::string header = format::EncodeHeader(h);
    old.replace(0, header.size(), header);
    store = OpenBytes(old);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->header().minor, 2);
    EXPECT_EQ((*store)->header().medium_grid, "");
    for (const BrickInfo& b : (*store)->bricks()) {
        EXPECT_EQ(b.medium.grid.length, 0u);
        EXPECT_TRUE((*store)->VerifyBrick(b.id).ok());
    }
}

TEST_F(StoreMedium, FlippedPieceByteIsReportedWithBrickAndOffset) {
    auto good = Store::Open(good_);
    ASSERT_TRUE(good.ok());
    const SectionInfo section = (*good)->bricks()[1].medium.grid;
    std::string bytes = bytes_;
    bytes[section.offset + 5] ^= 0x20;
    auto store = OpenBytes(bytes);
    ASSERT_TRUE(store.ok()) << "a piece is read on demand: " << store.status().ToString();
    const std::string at = fmt::format("brick 1 @0x{:x}", section.offset);
    ExpectError((*store)->ReadBrickMedium(1).status(), StatusCode::kDataLoss,
                {"bad.nave", at, "medium checksum", ChecksumHex(section.checksum)});
    ExpectError((*store)->VerifyBrick(1), StatusCode::kDataLoss, {at, "medium checksum"});
    EXPECT_TRUE((*store)->VerifyBrick(0).ok());
    EXPECT_TRUE((*store)->ReadBrick(1).ok()) << "the brick's mesh is intact";
}

TEST_F(StoreMedium, DamagedTableIsRefusedNamingTheBrick) {
    // Brick 1's entry: after the prefix, the name and brick 0's entry.
    const uint64_t entry = header_.medium.offset + format::kMediumPrefixBytes + 4 +
                           std::strlen("density") + format::kMediumEntryBytes;
    {
        std::string bytes = bytes_;
        const uint64_t zero = 0;
        std::memcpy(&bytes[entry + 24], &zero, 8);  // no voxels, yet a section
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {"bad.nave brick 1 medium", "0 voxels"});
    }
    {
        std::string bytes = bytes_;
        const float negative = -1;
        std::memcpy(&bytes[entry + 32], &negative, 4);
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {"brick 1 medium", "majorant -1"});
    }
    {
        std::string bytes = bytes_;
        const uint64_t far = bytes.size();
        std::memcpy(&bytes[entry], &far, 8);
        ExpectError(OpenBytes(Resealed(bytes)).status(), StatusCode::kDataLoss,
                    {"brick 1 medium", "outside the payload area"});
    }
    {
        std::string bytes = bytes_;
        bytes[header_.medium.offset + 20] ^= 1;  // not resealed
        ExpectError(OpenBytes(bytes).status(), StatusCode::kDataLoss, {"medium table", "checksum"});
    }
}

TEST_F(StoreMedium, WriterRefusesPiecesItCannotStore) {
    auto writer = StoreWriter::Create(dir_ / "refused.nave", grid_, {});
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE((*writer)->Append(EmptyBrick({})).ok());
    ExpectError((*writer)->AppendMedium(0, Piece("x", 1, 1)), StatusCode::kInvalidArgument,
                {"before SetMediumGrid"});
    ASSERT_TRUE((*writer)->SetMediumGrid("density").ok());
    ExpectError((*writer)->SetMediumGrid("other"), StatusCode::kInvalidArgument,
                {"'density' already"});
    ExpectError((*writer)->AppendMedium(1, Piece("x", 1, 1)), StatusCode::kInvalidArgument,
                {"brick 1 was not appended"});
    ExpectError((*writer)->AppendMedium(0, Piece("x", 0, 1)), StatusCode::kInvalidArgument,
                {"0 voxels"});
    ExpectError((*writer)->AppendMedium(0, Piece("x", 1, -2)), StatusCode::kInvalidArgument,
                {"majorant -2"});
    ASSERT_TRUE((*writer)->AppendMedium(0, Piece("x", 1, 1)).ok());
    ExpectError((*writer)->AppendMedium(0, Piece("y", 1, 1)), StatusCode::kInvalidArgument,
                {"already"});
}

}  // namespace
}  // namespace nave::store
