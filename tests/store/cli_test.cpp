// End to end: `nave inspect` and `nave verify` run as a user runs them, on a small store and a
// damaged copy.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>

#include "common/run_nave.h"
#include "src/core/file.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "store/testing/store_testing.h"
#include "test_util.h"

namespace nave::store {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::Streams;
using test::ScratchDir;

/// Stdout only unless `with_stderr` (JSON output is parsed from stdout alone).
CommandResult RunNave(const std::string& args, bool with_stderr = false) {
    return ::nave::test::RunNave(args,
                                 with_stderr ? Streams::kStdoutAndStderr : Streams::kStdoutOnly);
}

class NaveCli : public ::testing::Test {
  protected:
    void SetUp() override {
        const BrickMesh mesh = testing::MakeSurface({.quads_x = 20, .quads_y = 20});
        triangles_ = mesh.TriangleCount();
        auto written = testing::WriteGridStore(store_, mesh, testing::MakeMaterials(3), {2, 2, 1},
                                               GlobalGrid{{0, 0, 0}, 1e-3});
        ASSERT_TRUE(written.ok()) << written.status().ToString();
    }
    ScratchDir dir_;
    std::filesystem::path store_ = dir_ / "small.nave";
    size_t triangles_ = 0;
};

TEST_F(NaveCli, VerifyIntactStoreSucceeds) {
    const CommandResult run = RunNave("-q verify " + store_.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("4 of 4 bricks intact"), std::string::npos) << run.output;
}

TEST_F(NaveCli, InspectJsonDescribesTheStore) {
    const CommandResult run = RunNave("inspect --json " + store_.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    for (const std::string& part :
         {fmt::format("\"triangles\": {},", triangles_),
          fmt::format("\"source_triangles\": {},", triangles_), std::string("\"bricks\": 4,"),
          fmt::format("\"format_version\": \"{}.{}\"", kFormatMajor, kFormatMinor),
          std::string("\"step\": 0.001"), std::string("\"max_axis_error\": 0.0005"),
          std::string("\"name\": \"m2\""), std::string("\"map_Kd\": \"textures/m1.png\""),
          std::string("\"source_files\": [\"synthetic-surface\"]"),
          fmt::format("\"bytes_on_disk\": {},", std::filesystem::file_size(store_))}) {
        EXPECT_NE(run.output.find(part), std::string::npos) << "missing " << part << " in\n"
                                                            << run.output;
    }
    EXPECT_EQ(run.output.front(), '{');
    EXPECT_EQ(run.output.substr(run.output.size() - 2), "}\n");

    const CommandResult text = RunNave("inspect --bricks " + store_.string());
    EXPECT_EQ(text.exit_code, 0);
    EXPECT_NE(text.output.find("bytes/triangle"), std::string::npos) << text.output;
    EXPECT_NE(text.output.find("max position error 0.5 mm per axis"), std::string::npos)
        << text.output;
}

TEST_F(NaveCli, VerifyDamagedStoreFailsNamingTheBrick) {
    auto store = Store::Open(store_);
    ASSERT_TRUE(store.ok());
    const BrickInfo brick = (*store)->bricks()[2];
    store->reset();
    auto bytes = ReadFileToString(store_);
    ASSERT_TRUE(bytes.ok());
    (*bytes)[brick.mesh.offset + 10] ^= 0x01;
    const std::filesystem::path damaged = dir_ / "damaged.nave";
    std::ofstream(damaged, std::ios::binary).write(bytes->data(), std::streamsize(bytes->size()));

    const CommandResult run = RunNave("-q verify " + damaged.string(), true);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find(fmt::format("brick 2: data loss: {} brick 2 @0x{:x}: mesh checksum",
                                          damaged.string(), brick.mesh.offset)),
              std::string::npos)
        << run.output;
    EXPECT_NE(run.output.find("3 of 4 bricks intact"), std::string::npos) << run.output;
    EXPECT_EQ(run.output.find("brick 1:"), std::string::npos) << run.output;

    const CommandResult json = RunNave("-q verify --json " + damaged.string());
    EXPECT_EQ(json.exit_code, 1);
    EXPECT_NE(json.output.find("\"ok\": false"), std::string::npos) << json.output;
    EXPECT_NE(json.output.find("{\"id\": 2, \"error\": \"data loss:"), std::string::npos)
        << json.output;
}

TEST_F(NaveCli, InspectAndVerifyCoverTheLevels) {
    const std::filesystem::path with_levels = dir_ / "levels.nave";
    EncodeOptions options;
    options.levels.relative_errors = {0.002, 0.05};
    // Two levels on this small surface: no border locked, and a second level that keeps up to
    // half of the first's triangles.
    options.levels.border_lock = LevelOptions::BorderLock::kNone;
    options.levels.max_kept_fraction = 0.5;
    ASSERT_TRUE(testing::WriteGridStore(
                    with_levels, testing::MakeSurface({.quads_x = 40, .quads_y = 40}),
                    testing::MakeMaterials(3), {2, 2, 1}, GlobalGrid{{0, 0, 0}, 1e-3}, options)
                    .ok());
    const CommandResult text = RunNave("inspect --bricks " + with_levels.string());
    ASSERT_EQ(text.exit_code, 0) << text.output;
    for (const char* part : {"% to the store without them", "level 1: 4 bricks",
                             "level 2: 4 bricks", "error max", "    level 2 "}) {
        EXPECT_NE(text.output.find(part), std::string::npos) << "missing " << part << " in\n"
                                                             << text.output;
    }
    const CommandResult json = RunNave("inspect --json " + with_levels.string());
    ASSERT_EQ(json.exit_code, 0);
    EXPECT_NE(json.output.find("{\"level\": 2, \"bricks\": 4, \"triangles\": "), std::string::npos)
        << json.output;
    EXPECT_NE(json.output.find("\"level_growth_percent\": "), std::string::npos) << json.output;
    EXPECT_NE(RunNave("inspect " + store_.string()).output.find("levels       none"),
              std::string::npos);

    EXPECT_EQ(RunNave("-q verify " + with_levels.string()).exit_code, 0);
    auto store = Store::Open(with_levels);
    ASSERT_TRUE(store.ok());
    const LevelInfo level = (*store)->bricks()[1].levels[0];
    store->reset();
    std::string bytes = ReadFileToString(with_levels).value();
    bytes[level.mesh.offset + 20] ^= 0x01;
    const std::filesystem::path damaged = dir_ / "damaged_level.nave";
    std::ofstream(damaged, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    const CommandResult run = RunNave("-q verify " + damaged.string(), true);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(
        run.output.find(fmt::format("brick 1 @0x{:x}: level 1 mesh checksum", level.mesh.offset)),
        std::string::npos)
        << run.output;
    EXPECT_NE(run.output.find("3 of 4 bricks intact"), std::string::npos) << run.output;
}

TEST_F(NaveCli, MissingOrForeignFilesFailCleanly) {
    CommandResult run = RunNave("verify " + (dir_ / "absent.nave").string(), true);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.output.find("absent.nave: no such file"), std::string::npos) << run.output;
    std::ofstream(dir_ / "text.nave") << "hello, not a store\n";
    run = RunNave("inspect " + (dir_ / "text.nave").string(), true);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.output.find("not a nave store"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace nave::store
