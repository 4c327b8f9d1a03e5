// Damaged stores: every kind of damage gives the right StatusCode and a message naming the file,
// the part (header, table, brick) and the byte offset; never a crash. Also the crash-safety of the
// writer.

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

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

std::string ReadAll(const std::filesystem::path& p) {
    auto s = ReadFileToString(p);
    NAVE_CHECK(s.ok()) << s.status().ToString();
    return *s;
}

std::string Hex(uint64_t v) { return fmt::format("0x{:x}", v); }

class StoreCorruption : public ::testing::Test {
  protected:
    void SetUp() override {
        const BrickMesh mesh = testing::MakeSurface({.quads_x = 16, .quads_y = 16});
        auto written = testing::WriteGridStore(good_, mesh, testing::MakeMaterials(3), {2, 2, 1},
                                               GlobalGrid{{0, 0, 0}, 1e-3});
        ASSERT_TRUE(written.ok()) << written.status().ToString();
        bytes_ = ReadAll(good_);
        auto header = format::DecodeHeader(bytes_, "x", bytes_.size());
        ASSERT_TRUE(header.ok()) << header.status().ToString();
        header_ = *header;
        auto store = Store::Open(good_);
        ASSERT_TRUE(store.ok());
        bricks_ = (*store)->bricks();
        ASSERT_EQ(bricks_.size(), 4u);
    }

    // Writes `bytes` as a new file and opens it.
    StatusOr<std::unique_ptr<Store>> OpenBytes(const std::string& bytes) {
        return test::OpenStoreBytes(bad_, bytes);
    }
    std::string Flipped(uint64_t offset) const {
        std::string b = bytes_;
        b[offset] = char(b[offset] ^ 0x5a);
        return b;
    }
    // Expects `status` to have `code` and a message containing every one of `parts`.
    static void ExpectError(const Status& status, StatusCode code,
                            std::initializer_list<std::string> parts) {
        EXPECT_EQ(status.code(), code) << status.ToString();
        for (const std::string& p : parts)
            EXPECT_NE(status.message().find(p), std::string::npos)
                << status.message() << "\n  lacks: " << p;
    }

    ScratchDir dir_;
    std::filesystem::path good_ = dir_ / "good.nave";
    std::filesystem::path bad_ = dir_ / "bad.nave";
    std::string bytes_;
    format::RawHeader header_;
    std::vector<BrickInfo> bricks_;
};

TEST_F(StoreCorruption, TruncatedFileIsDataLoss) {
    const uint64_t n = bytes_.size();
    for (uint64_t length :
         {uint64_t(3), uint64_t(12), uint64_t(100), uint64_t(format::kHeaderBytes),
          uint64_t(format::kHeaderBytes + 7), bricks_[2].mesh.offset + 5, header_.directory.offset,
          header_.materials.offset + 3, n - 1}) {
        SCOPED_TRACE("length " + std::to_string(length));
        auto store = OpenBytes(bytes_.substr(0, length));
        ASSERT_FALSE(store.ok());
        ExpectError(store.status(), StatusCode::kDataLoss, {bad_.string(), "truncated"});
    }
}

TEST_F(StoreCorruption, AppendedBytesAreDataLoss) {
    auto store = OpenBytes(bytes_ + "tail");
    ExpectError(store.status(), StatusCode::kDataLoss, {bad_.string(), "extra bytes appended"});
}

TEST_F(StoreCorruption, FlippedHeaderByteIsDataLoss) {
    for (uint64_t offset : {20, 60, 100, 150, 250}) {
        SCOPED_TRACE("offset " + std::to_string(offset));
        auto store = OpenBytes(Flipped(offset));
        ExpectError(store.status(), StatusCode::kDataLoss,
                    {bad_.string(), "header @0x0: checksum", "!= stored"});
    }
}

TEST_F(StoreCorruption, FlippedTableByteNamesTheTableAndItsOffset) {
    struct Case {
        const char* table;
        SectionInfo ref;
    };
    for (const Case& c :
         {Case{"provenance", header_.provenance}, Case{"directory", header_.directory},
          Case{"tree", header_.tree}, Case{"materials", header_.materials},
          Case{"occupancy", header_.occupancy}}) {
        SCOPED_TRACE(c.table);
        for (uint64_t at :
             {c.ref.offset, c.ref.offset + c.ref.length / 2, c.ref.offset + c.ref.length - 1}) {
            auto store = OpenBytes(Flipped(at));
            ASSERT_FALSE(store.ok());
            ExpectError(store.status(), StatusCode::kDataLoss,
                        {bad_.string(),
                         std::string(c.table) + " table @" + Hex(c.ref.offset) + ": checksum"});
        }
    }
}

TEST_F(StoreCorruption, FlippedBrickByteIsReportedWithBrickAndOffset) {
    const BrickInfo& b = bricks_[2];
    auto store = OpenBytes(Flipped(b.mesh.offset + b.mesh.length / 2));
    ASSERT_TRUE(store.ok()) << "Open reads no brick payload: " << store.status().ToString();
    for (uint32_t id : {0u, 1u, 3u}) EXPECT_TRUE((*store)->VerifyBrick(id).ok());
    const Status s = (*store)->ReadBrick(2).status();
    ExpectError(s, StatusCode::kDataLoss,
                {bad_.string() + " brick 2 @" + Hex(b.mesh.offset) + ": mesh checksum",
                 "!= stored " + ChecksumHex(b.mesh.checksum)});
    EXPECT_EQ((*store)->VerifyBrick(2).code(), StatusCode::kDataLoss);
}

// A brick's occupancy grid (format 3.4) is read when a renderer opens the store: a damaged one is
// named with its brick and offset, and `nave verify` (VerifyBrick) finds it too.
TEST_F(StoreCorruption, FlippedOccupancyByteIsReportedWithBrickAndOffset) {
    const BrickInfo& b = bricks_[1];
    ASSERT_GT(b.occupancy.length, 0u) << "every brick with triangles has its grid";
    auto good = Store::Open(good_);
    ASSERT_TRUE(good.ok());
    StatusOr<OccupancyGrid> grid = (*good)->ReadBrickOccupancy(1);
    ASSERT_TRUE(grid.ok()) << grid.status().ToString();
    EXPECT_GT(grid->MarkedFraction(), 0.0);
    auto store = OpenBytes(Flipped(b.occupancy.offset + b.occupancy.length / 2));
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    ExpectError((*store)->ReadBrickOccupancy(1).status(), StatusCode::kDataLoss,
                {bad_.string() + " brick 1 @" + Hex(b.occupancy.offset) + ": occupancy checksum"});
    EXPECT_EQ((*store)->VerifyBrick(1).code(), StatusCode::kDataLoss);
    EXPECT_TRUE((*store)->VerifyBrick(0).ok());
}

// The checksums catch damage; this checks what is behind them. A payload changed and re-checksummed
// (as a buggy writer would produce) must still give an error or a mesh consistent with the
// directory, never a crash (run it under the asan preset).
TEST_F(StoreCorruption, DamagedPayloadBehindValidChecksumsNeverCrashes) {
    std::mt19937 rng(99);
    const BrickInfo& b = bricks_[1];
    int errors = 0;
    for (int trial = 0; trial < 60; ++trial) {
        std::string bytes = bytes_;
        std::uniform_int_distribution<uint64_t> pos(b.mesh.offset,
                                                    b.mesh.offset + b.mesh.length - 1);
        for (int k = 0; k < 1 + trial % 3; ++k) bytes[pos(rng)] ^= char(1 << (trial % 8));
        // Re-checksum the mesh section, the directory and the header.
        const uint64_t mesh_sum = Checksum64(bytes.data() + b.mesh.offset, b.mesh.length);
        const uint64_t entry = header_.directory.offset + 1 * format::kDirectoryEntryBytes;
        std::memcpy(&bytes[entry + 96], &mesh_sum, 8);
        format::RawHeader h = header_;
        h.directory.checksum = Checksum64(bytes.data() + h.directory.offset, h.directory.length);
        const std::string header = format::EncodeHeader(h);
        bytes.replace(0, header.size(), header);
        auto store = OpenBytes(bytes);
        ASSERT_TRUE(store.ok()) << store.status().ToString();
        auto read = (*store)->ReadBrick(1);
        if (!read.ok()) {
            ++errors;
            ExpectError(read.status(), StatusCode::kDataLoss,
                        {bad_.string() + " brick 1 @" + Hex(b.mesh.offset)});
        } else {
            EXPECT_EQ(read->TriangleCount(), b.triangle_count);
        }
    }
    EXPECT_GT(errors, 0);
}

// Tables that pass their checksums but make no sense (what a buggy writer could produce) are
// refused too.
TEST_F(StoreCorruption, InconsistentTablesBehindValidChecksumsAreRefused) {
    auto rechecksum = [&](std::string bytes) {
        format::RawHeader h = header_;
        for (SectionInfo* t : {&h.provenance, &h.directory, &h.tree, &h.materials}) {
            t->checksum = Checksum64(bytes.data() + t->offset, t->length);
        }
        const std::string header = format::EncodeHeader(h);
        return bytes.replace(0, header.size(), header);
    };
    const uint64_t entry1 = header_.directory.offset + format::kDirectoryEntryBytes;
    {
        std::string bytes = bytes_;
        const uint64_t past_end = header_.materials.offset + 100;
        std::memcpy(&bytes[entry1 + 80], &past_end, 8);  // brick 1's mesh offset
        auto store = OpenBytes(rechecksum(bytes));
        ExpectError(store.status(), StatusCode::kDataLoss,
                    {bad_.string() + " brick 1 @" + Hex(entry1), "mesh section",
                     "outside the payload area"});
    }
    {
        std::string bytes = bytes_;
        const uint32_t wrong_id = 7;
        std::memcpy(&bytes[entry1], &wrong_id, 4);
        auto store = OpenBytes(rechecksum(bytes));
        ExpectError(store.status(), StatusCode::kDataLoss, {"brick 1", "says id 7"});
    }
    {
        std::string bytes = bytes_;
        const uint64_t triangles = bricks_[1].triangle_count + 1;
        std::memcpy(&bytes[entry1 + 56], &triangles, 8);  // also breaks decoded bytes and the total
        auto store = OpenBytes(rechecksum(bytes));
        ExpectError(store.status(), StatusCode::kDataLoss, {"brick 1", "decoded size"});
    }
    {
        // The root's second child pointed back at the root: a cycle.
        std::string bytes = bytes_;
        const uint32_t root = 0;
        std::memcpy(&bytes[header_.tree.offset + 24 + 12], &root, 4);
        auto store = OpenBytes(rechecksum(bytes));
        ExpectError(store.status(), StatusCode::kDataLoss,
                    {bad_.string() + " tree @" + Hex(header_.tree.offset)});
    }
    {
        // A material record that claims more bytes than the table holds.
        std::string bytes = bytes_;
        const uint32_t huge = 1u << 30;
        std::memcpy(&bytes[header_.materials.offset], &huge, 4);
        auto store = OpenBytes(rechecksum(bytes));
        ExpectError(store.status(), StatusCode::kDataLoss, {"material 0", "overruns the table"});
    }
}

// Random damage to the tables with every checksum recomputed: Open and ReadBrick must return a
// Status or work, never crash or allocate without bound (run under the asan preset).
TEST_F(StoreCorruption, RandomTableDamageBehindValidChecksumsNeverCrashes) {
    std::mt19937 rng(2024);
    const uint64_t tables_begin = header_.provenance.offset;
    std::uniform_int_distribution<uint64_t> pos(tables_begin, bytes_.size() - 1);
    int refused = 0;
    for (int trial = 0; trial < 120; ++trial) {
        std::string bytes = bytes_;
        for (int k = 0; k < 1 + trial % 4; ++k) bytes[pos(rng)] ^= char(1 + rng() % 255);
        format::RawHeader h = header_;
        for (SectionInfo* t : {&h.provenance, &h.directory, &h.tree, &h.materials}) {
            t->checksum = Checksum64(bytes.data() + t->offset, t->length);
        }
        const std::string header = format::EncodeHeader(h);
        bytes.replace(0, header.size(), header);
        auto store = OpenBytes(bytes);
        if (!store.ok()) {
            ++refused;
            EXPECT_EQ(store.status().code(), StatusCode::kDataLoss) << store.status().ToString();
            continue;
        }
        for (uint32_t b = 0; b < (*store)->bricks().size(); ++b) {
            const Status s = (*store)->VerifyBrick(b);
            if (!s.ok()) {
                EXPECT_TRUE(s.code() == StatusCode::kDataLoss || s.code() == StatusCode::kNotFound)
                    << s.ToString();
            }
        }
    }
    EXPECT_GT(refused, 20);
}

TEST_F(StoreCorruption, FutureMajorVersionIsRefusedNamingBothVersions) {
    format::RawHeader h = header_;
    h.major = kFormatMajor + 1;
    h.minor = 3;
    std::string bytes = bytes_;
    const std::string header = format::EncodeHeader(h);
    bytes.replace(0, header.size(), header);
    auto store = OpenBytes(bytes);
    ExpectError(store.status(), StatusCode::kUnsupported,
                {bad_.string(), fmt::format("version {}.3", kFormatMajor + 1),
                 fmt::format("reads versions {}.x to {}.x", kOldestReadableMajor, kFormatMajor),
                 "newer nave"});
}

TEST_F(StoreCorruption, NewerMinorVersionStillOpens) {
    format::RawHeader h = header_;
    h.minor = kFormatMinor + 4;
    std::string bytes = bytes_;
    const std::string header = format::EncodeHeader(h);
    bytes.replace(0, header.size(), header);
    auto store = OpenBytes(bytes);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    EXPECT_EQ((*store)->header().minor, kFormatMinor + 4);
    EXPECT_TRUE((*store)->VerifyBrick(0).ok());
}

TEST_F(StoreCorruption, EmptyFileIsDataLoss) {
    auto store = OpenBytes("");
    ExpectError(store.status(), StatusCode::kDataLoss, {bad_.string(), "empty file"});
}

TEST_F(StoreCorruption, OtherFileIsNotAStore) {
    auto store = OpenBytes("ply\nformat ascii 1.0\nelement vertex 8\n");
    ExpectError(store.status(), StatusCode::kUnsupported,
                {bad_.string(), "not a nave store", "magic \"ply\\x0aform\""});
    store = OpenBytes(Flipped(2));  // the magic itself damaged
    ExpectError(store.status(), StatusCode::kUnsupported, {"not a nave store"});
}

TEST_F(StoreCorruption, MissingFileIsNotFound) {
    auto store = Store::Open(dir_ / "nowhere.nave");
    ExpectError(store.status(), StatusCode::kNotFound, {"nowhere.nave"});
}

TEST_F(StoreCorruption, BrickIdOutOfRangeIsNotFound) {
    auto store = Store::Open(good_);
    ASSERT_TRUE(store.ok());
    ExpectError((*store)->ReadBrick(4).status(), StatusCode::kNotFound,
                {"brick 4 does not exist", "4 bricks"});
}

TEST(StoreWriterCrashSafety, WriterDestroyedBeforeFinishLeavesNoFile) {
    ScratchDir dir;
    const GlobalGrid grid{{0, 0, 0}, 1e-3};
    const BrickMesh mesh = testing::MakeSurface({.quads_x = 8, .quads_y = 8});
    {
        auto writer = StoreWriter::Create(dir / "cut.nave", grid, {});
        ASSERT_TRUE(writer.ok());
        auto brick = EncodeBrick(mesh, {}, grid, {});
        ASSERT_TRUE(brick.ok());
        ASSERT_TRUE((*writer)->Append(*brick).ok());
        EXPECT_EQ(dir.Files().size(), 1u);  // the temporary file, under another name
        EXPECT_FALSE(std::filesystem::exists(dir / "cut.nave"));
        EXPECT_GT((*writer)->bytes_written(), brick->mesh_bytes.size());
    }
    EXPECT_TRUE(dir.Files().empty());
}

TEST(StoreWriterCrashSafety, CopyOfAnUnfinishedTemporaryFileDoesNotOpen) {
    // What a crash (kill -9) leaves: the temporary file with payloads and a zero header.
    ScratchDir dir;
    const GlobalGrid grid{{0, 0, 0}, 1e-3};
    auto writer = StoreWriter::Create(dir / "cut.nave", grid, {});
    ASSERT_TRUE(writer.ok());
    auto brick = EncodeBrick(testing::MakeSurface({.quads_x = 4, .quads_y = 4}), {}, grid, {});
    ASSERT_TRUE(brick.ok());
    ASSERT_TRUE((*writer)->Append(*brick).ok());
    const std::string temp = dir.Files().at(0);
    std::filesystem::copy_file(dir / temp, dir / "crashed.nave");
    auto store = Store::Open(dir / "crashed.nave");
    EXPECT_EQ(store.status().code(), StatusCode::kDataLoss) << store.status().ToString();
    EXPECT_NE(store.status().message().find("writing never finished"), std::string::npos);
}

}  // namespace
}  // namespace nave::store
