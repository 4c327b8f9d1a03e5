// VdbPlugin::CutScalarGrid: a grid cut along boxes gives, for each box, the active voxels whose
// cells overlap it (a voxel on a border goes to both sides), each piece reads back with
// ReadScalarGridBytes with the same values, the voxels no box holds are counted, and bad files
// and grids are refused naming the file, the grid or the voxel.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <tuple>

#include "common/scratch_dir.h"
#include "src/volumes/vdb_plugin.h"
#include "voxel_cells.h"

namespace nave::volumes {
namespace {

using ::testing::HasSubstr;

constexpr float kVoxel = 0.5f;
const Vec3f kOrigin(0, 0, 0);
const Vec3i kDims(10, 6, 4);

/// The test grid's value at voxel ijk: 0 (inactive) on a diagonal pattern, else distinct values.
float Value(int i, int j, int k) {
    if ((i + 2 * j + k) % 5 == 0) return 0.f;
    return 1.f + float(i) + 10.f * float(j) + 100.f * float(k);
}

/// Voxel ijk's cell overlaps `box` (closed).
bool CellOverlaps(int i, int j, int k, const Bounds3f& box) {
    return test::VoxelCellOverlaps(kOrigin, kVoxel, i, j, k, box);
}

class VdbCut : public ::testing::Test {
  protected:
    void SetUp() override {
        auto plugin = LoadVdbPlugin();
        ASSERT_TRUE(plugin.ok()) << plugin.status().ToString();
        plugin_ = *plugin;
        ASSERT_TRUE(plugin_->WriteScalarGrid(file_, "density", kOrigin, kVoxel, kDims, Value).ok());
    }

    /// Cuts `file_` along `boxes`, keeping the pieces by box.
    StatusOr<GridCutSummary> Cut(const std::filesystem::path& file, const std::string& grid,
                                 const std::vector<Bounds3f>& boxes) {
        pieces_.clear();
        return plugin_->CutScalarGrid(
            file, grid, boxes, /*memory_limit=*/0, [&](size_t box, GridPiece piece) {
                EXPECT_TRUE(pieces_.empty() || pieces_.rbegin()->first < box) << "in order of box";
                pieces_.emplace(box, std::move(piece));
                return Status::Ok();
            });
    }

    test::ScratchDir dir_{"vdb_cut"};
    std::filesystem::path file_ = dir_ / "dust.vdb";
    const VdbPlugin* plugin_ = nullptr;
    std::map<size_t, GridPiece> pieces_;
};

TEST_F(VdbCut, PiecesHoldTheVoxelsWhoseCellsOverlapTheirBoxAndReadBack) {
    // Along x: a split on a cell border (1.0: the cells on both sides touch it), one through the
    // middle of cells (2.25), and nothing past 3.5, so the cells from x = 4 on lie in no box. A
    // fourth box lies away from the grid.
    const float y0 = -1, y1 = 10, z0 = -1, z1 = 10;
    const std::vector<Bounds3f> boxes = {
        Bounds3f(Vec3f(-1, y0, z0), Vec3f(1, y1, z1)),
        Bounds3f(Vec3f(1, y0, z0), Vec3f(2.25f, y1, z1)),
        Bounds3f(Vec3f(2.25f, y0, z0), Vec3f(3.5f, y1, z1)),
        Bounds3f(Vec3f(20, 20, 20), Vec3f(21, 21, 21)),
    };
    auto summary = Cut(file_, "density", boxes);
    ASSERT_TRUE(summary.ok()) << summary.status().ToString();

    uint64_t active = 0, outside = 0, in_pieces = 0, straddlers = 0;
    std::vector<uint64_t> expected(boxes.size(), 0);
    std::vector<float> expected_max(boxes.size(), 0);
    for (int k = 0; k < kDims.z; ++k)
        for (int j = 0; j < kDims.y; ++j)
            for (int i = 0; i < kDims.x; ++i) {
                if (Value(i, j, k) == 0) continue;
                ++active;
                int holders = 0;
                for (size_t b = 0; b < boxes.size(); ++b) {
                    if (!CellOverlaps(i, j, k, boxes[b])) continue;
                    ++holders;
                    ++expected[b];
                    expected_max[b] = std::max(expected_max[b], Value(i, j, k));
                }
                outside += holders == 0;
                straddlers += holders > 1 ? holders - 1 : 0;
            }
    EXPECT_EQ(summary->active_voxels, active);
    EXPECT_EQ(summary->voxels_outside, outside);
    EXPECT_GT(outside, 0u);
    EXPECT_GT(straddlers, 0u);
    EXPECT_EQ(summary->bounds, Bounds3f(Vec3f(0, 0, 0), Vec3f(5, 3, 2)));
    EXPECT_EQ(pieces_.size(), 3u) << "the box away from the grid gets no piece";

    for (const auto& entry : pieces_) {
        // Not a structured binding: clang before 16 (the fuzz preset's) cannot capture one.
        const size_t b = entry.first;
        const GridPiece& piece = entry.second;
        SCOPED_TRACE(::testing::Message() << "box " << b);
        EXPECT_EQ(piece.active_voxels, expected[b]);
        EXPECT_EQ(piece.max_value, expected_max[b]);
        in_pieces += piece.active_voxels;
        auto read = plugin_->ReadScalarGridBytes(piece.bytes, "piece");
        ASSERT_TRUE(read.ok()) << read.status().ToString();
        EXPECT_EQ((*read)->active_voxels(), piece.active_voxels);
        EXPECT_EQ((*read)->memory_bytes(), piece.memory_bytes);
        // Along x through every row of voxel centres: the piece's voxels have the source's
        // values, the others are 0.
        for (int k = 0; k < kDims.z; ++k)
            for (int j = 0; j < kDims.y; ++j) {
                const Vec3f o(-2, (float(j) + 0.5f) * kVoxel, (float(k) + 0.5f) * kVoxel);
                (*read)->March(o, Vec3f(1, 0, 0), 0, 10, [&](float t0, float t1, float value) {
                    const int i = int(std::floor((o.x + 0.5f * (t0 + t1)) / kVoxel));
                    const bool held = i >= 0 && i < kDims.x && CellOverlaps(i, j, k, boxes[b]);
                    EXPECT_EQ(value, held ? Value(i, j, k) : 0.f) << i << " " << j << " " << k;
                    return true;
                });
            }
    }
    EXPECT_EQ(in_pieces, active - outside + straddlers);
}

// What the fuzz target (tests/fuzz/fuzz_vdb_bytes.cpp) does at random, here at every cut length.
TEST_F(VdbCut, CutShortPiecesAreDataLossNamingThem) {
    auto summary = Cut(file_, "density", {Bounds3f(Vec3f(0, 0, 0), Vec3f(5, 3, 2))});
    ASSERT_TRUE(summary.ok()) << summary.status().ToString();
    ASSERT_EQ(pieces_.size(), 1u);
    const std::vector<std::byte>& bytes = pieces_.begin()->second.bytes;
    for (size_t n = 0; n < bytes.size(); n += std::max<size_t>(1, bytes.size() / 97)) {
        auto read = plugin_->ReadScalarGridBytes(std::span(bytes.data(), n), "brick 3 medium");
        if (read.ok()) continue;  // a prefix may hold a whole grid, the rest being padding
        EXPECT_EQ(read.status().code(), StatusCode::kDataLoss) << n;
        EXPECT_THAT(read.status().message(), HasSubstr("brick 3 medium")) << n;
    }
}

// What a cut holds at once is measured, and a limit below it is refused before a box's values
// are read, naming the file, the grid and the box; a limit above it changes nothing.
TEST_F(VdbCut, AMemoryLimitBoundsWhatTheCutHolds) {
    const std::vector<Bounds3f> boxes = {Bounds3f(Vec3f(-1, -1, -1), Vec3f(2, 9, 9)),
                                         Bounds3f(Vec3f(2, -1, -1), Vec3f(9, 9, 9))};
    auto free = Cut(file_, "density", boxes);
    ASSERT_TRUE(free.ok()) << free.status().ToString();
    EXPECT_GT(free->topology_bytes, 0u);
    EXPECT_GT(free->peak_bytes, free->topology_bytes);
    const std::map<size_t, GridPiece> unlimited = std::move(pieces_);

    auto cut_within = [&](uint64_t limit) {
        pieces_.clear();
        return plugin_->CutScalarGrid(file_, "density", boxes, limit,
                                      [&](size_t box, GridPiece piece) {
                                          pieces_.emplace(box, std::move(piece));
                                          return Status::Ok();
                                      });
    };
    // The estimate holds what was measured: a limit at the measured peak may still be refused,
    // one at four times it is not.
    auto roomy = cut_within(4 * free->peak_bytes);
    ASSERT_TRUE(roomy.ok()) << roomy.status().ToString();
    ASSERT_EQ(pieces_.size(), unlimited.size());
    for (const auto& entry : unlimited) {
        // Not the bytes: OpenVDB's archive header carries a UUID of its own.
        EXPECT_EQ(pieces_.at(entry.first).active_voxels, entry.second.active_voxels);
        EXPECT_EQ(pieces_.at(entry.first).max_value, entry.second.max_value);
        EXPECT_EQ(pieces_.at(entry.first).memory_bytes, entry.second.memory_bytes);
    }

    auto tight = cut_within(2 * free->topology_bytes + 1);
    ASSERT_FALSE(tight.ok());
    EXPECT_EQ(tight.status().code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(tight.status().message(),
                HasSubstr("dust.vdb: grid 'density': the piece for box 0"));
    EXPECT_TRUE(pieces_.empty()) << "refused before any piece";

    auto none = cut_within(free->topology_bytes);
    ASSERT_FALSE(none.ok());
    EXPECT_THAT(none.status().message(), HasSubstr("its topology alone"));
    auto checked = plugin_->CutScalarGrid(file_, "density", {}, free->topology_bytes,
                                          [](size_t, const GridPiece&) { return Status::Ok(); });
    EXPECT_EQ(checked.status().code(), StatusCode::kResourceExhausted)
        << "checked with no boxes too";
}

TEST_F(VdbCut, NoBoxesChecksTheGridAndCountsItsVoxels) {
    auto summary = Cut(file_, "density", {});
    ASSERT_TRUE(summary.ok()) << summary.status().ToString();
    EXPECT_EQ(summary->voxels_outside, summary->active_voxels);
    EXPECT_GT(summary->active_voxels, 0u);
    EXPECT_TRUE(pieces_.empty());
}

TEST_F(VdbCut, EmitErrorStopsTheCut) {
    int calls = 0;
    auto summary = plugin_->CutScalarGrid(
        file_, "density", std::vector<Bounds3f>(3, Bounds3f(Vec3f(0, 0, 0), Vec3f(5, 5, 5))),
        /*memory_limit=*/0, [&](size_t, const GridPiece&) {
            ++calls;
            return IoError("disk full");
        });
    EXPECT_EQ(summary.status().code(), StatusCode::kIoError);
    EXPECT_EQ(calls, 1);
}

TEST_F(VdbCut, BadFilesAndGridsAreNamed) {
    const std::vector<Bounds3f> all = {Bounds3f(Vec3f(-1, -1, -1), Vec3f(9, 9, 9))};
    auto missing = Cut(file_, "smoke", all);
    EXPECT_EQ(missing.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(missing.status().message(), HasSubstr("dust.vdb: no grid 'smoke'"));
    EXPECT_THAT(missing.status().message(), HasSubstr("grids there: density"));

    const auto garbage = dir_ / "garbage.vdb";
    std::ofstream(garbage, std::ios::binary) << "these bytes are no OpenVDB file at all";
    auto not_vdb = Cut(garbage, "density", all);
    EXPECT_EQ(not_vdb.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(not_vdb.status().message(), HasSubstr("garbage.vdb: not a readable OpenVDB file"));

    // A file cut short anywhere is refused naming it, before OpenVDB's reader would take bytes
    // past its end for a length and allocate gigabytes: every 97th length, and the last byte.
    const std::string whole = [&] {
        std::ifstream in(file_, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    const auto cut = dir_ / "cut.vdb";
    std::vector<size_t> lengths;
    for (size_t length = 0; length < whole.size(); length += 97) lengths.push_back(length);
    lengths.push_back(whole.size() - 1);
    for (const size_t length : lengths) {
        std::ofstream(cut, std::ios::binary | std::ios::trunc) << whole.substr(0, length);
        auto refused = Cut(cut, "density", all);
        ASSERT_FALSE(refused.ok()) << length << " bytes";
        EXPECT_THAT(refused.status().message(), HasSubstr("cut.vdb")) << length << " bytes";
    }

    EXPECT_EQ(Cut(dir_ / "absent.vdb", "density", all).status().code(), StatusCode::kNotFound);

    const auto negative = dir_ / "negative.vdb";
    ASSERT_TRUE(plugin_
                    ->WriteScalarGrid(negative, "density", kOrigin, kVoxel, Vec3i(4, 4, 4),
                                      [](int i, int j, int k) {
                                          return i == 2 && j == 1 && k == 3 ? -0.5f : 1.f;
                                      })
                    .ok());
    auto refused = Cut(negative, "density", all);
    EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(refused.status().message(), HasSubstr("negative.vdb: grid 'density'"));
    EXPECT_THAT(refused.status().message(), HasSubstr("density -0.5 at voxel (2, 1, 3)"));
}

}  // namespace
}  // namespace nave::volumes
