// A medium given beside the model (`nave preprocess model.obj dust.vdb`): every brick holds the
// grid's voxels whose cells overlap its cell, a cell with voxels and no triangles gets a brick of
// no triangles, voxels outside the model's box are dropped and counted, and a bad .vdb stops the
// run naming the file and the grid, leaving nothing behind.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "common/list_names.h"
#include "common/run_nave.h"
#include "common/scratch_dir.h"
#include "preprocess/medium_cut.h"
#include "preprocess/preprocess.h"
#include "src/volumes/vdb_plugin.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "voxel_cells.h"

namespace nave::preprocess {
namespace {

using ::testing::HasSubstr;

constexpr float kVoxel = 0.5f;
const Vec3f kOrigin(-0.5f, -0.5f, -0.5f);
const Vec3i kDims(11, 11, 11);

float Dust(int i, int j, int k) {
    if ((i * 7 + j * 3 + k) % 4 == 0) return 0.f;
    return 0.25f * float(1 + (i + j + k) % 9);
}

/// Voxel ijk's cell overlaps `box` (closed).
bool CellOverlaps(int i, int j, int k, const Bounds3f& box) {
    return test::VoxelCellOverlaps(kOrigin, kVoxel, i, j, k, box);
}

/// Active voxels of Dust whose cells overlap `box`.
uint64_t VoxelsIn(const Bounds3f& box) {
    uint64_t n = 0;
    for (int k = 0; k < kDims.z; ++k)
        for (int j = 0; j < kDims.y; ++j)
            for (int i = 0; i < kDims.x; ++i)
                n += Dust(i, j, k) != 0 && CellOverlaps(i, j, k, box) ? 1 : 0;
    return n;
}

/// Two sheets of 24 x 24 quads, at z = 0 and z = 4, over [0, 4]^2: 2304 triangles.
void WriteSheets(const std::filesystem::path& path) {
    constexpr int kSide = 24;
    std::ofstream obj(path);
    for (int z : {0, 4})
        for (int y = 0; y <= kSide; ++y)
            for (int x = 0; x <= kSide; ++x)
                obj << "v " << 4.0 * x / kSide << " " << 4.0 * y / kSide << " " << z << "\n";
    const int per_sheet = (kSide + 1) * (kSide + 1);
    for (int s = 0; s < 2; ++s)
        for (int y = 0; y < kSide; ++y)
            for (int x = 0; x < kSide; ++x) {
                const int a = s * per_sheet + y * (kSide + 1) + x + 1, b = a + 1, c = a + kSide + 1,
                          d = c + 1;
                obj << "f " << a << " " << b << " " << d << "\nf " << a << " " << d << " " << c
                    << "\n";
            }
}

class PreprocessMedium : public ::testing::Test {
  protected:
    void SetUp() override {
        auto plugin = volumes::LoadVdbPlugin();
        ASSERT_TRUE(plugin.ok()) << plugin.status().ToString();
        plugin_ = *plugin;
        ASSERT_TRUE(plugin_->WriteScalarGrid(vdb_, "density", kOrigin, kVoxel, kDims, Dust).ok());
        WriteSheets(model_);
    }

    PreprocessOptions Options(const std::filesystem::path& vdb) const {
        PreprocessOptions o;
        o.inputs = {model_, vdb};
        o.output = out_;
        o.brick_triangles = 1000;
        o.threads = 2;
        o.memory_bytes = 256 << 20;
        return o;
    }

    /// The run fails with `code` and a message holding `parts`, and leaves no file but the inputs.
    void ExpectRefused(const PreprocessOptions& o, StatusCode code,
                       std::initializer_list<std::string> parts) {
        auto stats = RunPreprocess(o);
        ASSERT_FALSE(stats.ok());
        EXPECT_EQ(stats.status().code(), code) << stats.status().ToString();
        for (const std::string& p : parts) EXPECT_THAT(stats.status().message(), HasSubstr(p));
        EXPECT_FALSE(std::filesystem::exists(out_));
        for (const std::string& name : test::ListNames(dir_.path()))
            EXPECT_THAT(name, ::testing::AnyOf("sheets.obj", "dust.vdb", "bad.vdb")) << "left";
    }

    test::ScratchDir dir_{"medium"};
    std::filesystem::path model_ = dir_ / "sheets.obj";
    std::filesystem::path vdb_ = dir_ / "dust.vdb";
    std::filesystem::path out_ = dir_ / "out.nave";
    const volumes::VdbPlugin* plugin_ = nullptr;
};

TEST_F(PreprocessMedium, EveryBrickHoldsTheVoxelsOfItsCell) {
    auto stats = RunPreprocess(Options(vdb_));
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();
    auto opened = store::Store::Open(out_);
    ASSERT_TRUE(opened.ok()) << opened.status().ToString();
    const store::Store& s = **opened;
    EXPECT_EQ(s.header().medium_grid, "density");
    EXPECT_THAT(s.header().provenance.source_files, ::testing::Contains(vdb_.string()));
    EXPECT_THAT(s.header().provenance.options, HasSubstr("medium-grid=density"));
    ASSERT_GE(s.bricks().size(), 2u);

    uint64_t stored = 0;
    for (const store::BrickInfo& b : s.bricks()) {
        SCOPED_TRACE(::testing::Message() << "brick " << b.id);
        const uint64_t expected = VoxelsIn(b.cell);
        EXPECT_EQ(b.medium.active_voxels, expected);
        stored += b.medium.active_voxels;
        if (expected == 0) continue;
        auto bytes = s.ReadBrickMedium(b.id);
        ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
        auto grid = plugin_->ReadScalarGridBytes(*bytes, "piece");
        ASSERT_TRUE(grid.ok()) << grid.status().ToString();
        EXPECT_EQ((*grid)->active_voxels(), expected);
        EXPECT_EQ((*grid)->memory_bytes(), b.medium.decoded_bytes);
        EXPECT_GT(b.medium.max_density, 0.f);
        EXPECT_TRUE(s.VerifyBrick(b.id).ok());
    }
    // The cells from x, y or z = 4.5 on lie outside the model's box (its bounds and a grid step).
    const Bounds3f root = s.tree().bounds();
    EXPECT_EQ(stats->medium_dropped_voxels,
              VoxelsIn(Bounds3f(kOrigin, Vec3f(6, 6, 6))) - VoxelsIn(root));
    EXPECT_GT(stats->medium_dropped_voxels, 0u);
    EXPECT_EQ(stats->medium_stored_voxels, stored);
    EXPECT_EQ(stats->medium_bricks, s.bricks().size());
    EXPECT_THAT(FormatSummary(*stats), HasSubstr("medium:      grid 'density'"));
    EXPECT_THAT(stats->warnings, ::testing::Contains(HasSubstr("were dropped")));
}

// Cut by hand along a tree of two leaves, the upper one empty: it gets a brick of no triangles.
TEST_F(PreprocessMedium, EmptyCellWithVoxelsGetsABrickWithoutTriangles) {
    const Bounds3f root(Vec3f(0, 0, 0), Vec3f(4, 4, 4));
    std::vector<store::BrickTreeNode> nodes(3);
    nodes[0].axis = 2;
    nodes[0].split = 1.1f;
    nodes[0].child[0] = 1;
    nodes[0].child[1] = 2;
    const store::GlobalGrid grid{{0, 0, 0}, 1e-3};
    auto writer = store::StoreWriter::Create(out_, grid, {});
    ASSERT_TRUE(writer.ok());
    store::BrickMesh triangle;
    triangle.positions = {{0, 0, 0.5f}, {1, 0, 0.5f}, {0, 1, 0.5f}};
    triangle.indices = {0, 1, 2};
    triangle.material_ids = {0};
    auto encoded = store::EncodeBrick(triangle, {}, grid, {});
    ASSERT_TRUE(encoded.ok());
    nodes[1].brick = (*writer)->Append(*encoded).value();

    PreprocessStats stats;
    ASSERT_TRUE(
        StoreMedium(vdb_, "density", root, /*memory_budget=*/0, nodes, **writer, &stats).ok());
    ASSERT_NE(nodes[2].brick, store::kNoBrick);
    EXPECT_EQ(stats.medium_only_bricks, 1u);
    EXPECT_EQ(stats.medium_bricks, 2u);
    EXPECT_EQ(stats.medium_dropped_voxels,
              VoxelsIn(Bounds3f(kOrigin, Vec3f(6, 6, 6))) - VoxelsIn(root));
    store::MaterialRecord material;
    material.name = "m";
    ASSERT_TRUE((*writer)->Finish({material}, store::BrickTree(root, nodes), 1).ok());

    auto s = store::Store::Open(out_);
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    const store::BrickInfo& empty = (*s)->bricks()[nodes[2].brick];
    EXPECT_EQ(empty.triangle_count, 0u);
    EXPECT_EQ(empty.cell, Bounds3f(Vec3f(0, 0, 1.1f), Vec3f(4, 4, 4)));
    EXPECT_EQ(empty.medium.active_voxels, VoxelsIn(empty.cell));
    auto mesh = (*s)->ReadBrick(empty.id);
    ASSERT_TRUE(mesh.ok()) << mesh.status().ToString();
    EXPECT_EQ(mesh->TriangleCount(), 0u);
    EXPECT_TRUE((*s)->VerifyBrick(empty.id).ok());
}

TEST_F(PreprocessMedium, BadGridStopsTheRunNamingFileAndGrid) {
    const auto bad = dir_ / "bad.vdb";
    std::ofstream(bad, std::ios::binary) << std::string(300, '\x5a');
    ExpectRefused(Options(bad), StatusCode::kDataLoss, {"bad.vdb", "not a readable OpenVDB"});

    std::filesystem::remove(bad);
    std::filesystem::copy_file(vdb_, bad);
    std::filesystem::resize_file(bad, std::filesystem::file_size(vdb_) * 2 / 3);
    ExpectRefused(Options(bad), StatusCode::kDataLoss, {"bad.vdb"});

    PreprocessOptions smoke = Options(vdb_);
    smoke.medium_grid = "smoke";
    ExpectRefused(smoke, StatusCode::kDataLoss, {"dust.vdb: no grid 'smoke'", "density"});

    std::filesystem::remove(bad);
    ASSERT_TRUE(plugin_
                    ->WriteScalarGrid(bad, "density", kOrigin, kVoxel, Vec3i(3, 3, 3),
                                      [](int i, int, int) { return i == 1 ? -2.f : 1.f; })
                    .ok());
    ExpectRefused(Options(bad), StatusCode::kDataLoss,
                  {"bad.vdb: grid 'density'", "density -2 at voxel (1, 0, 0)"});

    PreprocessOptions two = Options(vdb_);
    two.inputs.push_back(bad);
    ExpectRefused(two, StatusCode::kInvalidArgument, {"dust.vdb and ", "bad.vdb"});
}

TEST_F(PreprocessMedium, CommandLineReportsTheMediumAndFailsOnBadGrids) {
    const std::string model = model_.string(), vdb = vdb_.string(), out = out_.string();
    test::CommandResult run = test::RunNave("preprocess " + model + " " + vdb + " -o " + out +
                                            " --brick-triangles 1000 --threads 2");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_THAT(run.output, HasSubstr("medium:      grid 'density' of " + vdb));
    EXPECT_THAT(run.output, HasSubstr("the cut held at most "));
    test::CommandResult inspect = test::RunNave("inspect --bricks " + out);
    EXPECT_EQ(inspect.exit_code, 0) << inspect.output;
    EXPECT_THAT(inspect.output, HasSubstr("medium       grid 'density': "));
    EXPECT_THAT(inspect.output, HasSubstr("majorant"));
    test::CommandResult json = test::RunNave("inspect --json " + out, test::Streams::kStdoutOnly);
    EXPECT_THAT(json.output, HasSubstr("\"medium\": {\"grid\": \"density\""));
    test::CommandResult verify = test::RunNave("verify " + out);
    EXPECT_EQ(verify.exit_code, 0) << verify.output;
    std::filesystem::remove(out_);

    const auto bad = dir_ / "bad.vdb";
    std::ofstream(bad, std::ios::binary) << "not a grid";
    run = test::RunNave("preprocess " + model + " " + bad.string() + " -o " + out);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_THAT(run.output, HasSubstr("bad.vdb"));
    EXPECT_FALSE(std::filesystem::exists(out_));
    run = test::RunNave("preprocess " + model + " " + vdb + " -o " + out + " --medium-grid smoke");
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_THAT(run.output, HasSubstr("no grid 'smoke' (grids there: density)"));
}

}  // namespace
}  // namespace nave::preprocess
