// A full disk during preprocess, made with a file size limit (test::ScopedFileSizeLimit): writes
// past it fail with EFBIG as they would with ENOSPC. Whether the temporary bins or the store hit
// it, the run fails with a message that names the directory or file it was writing and what failed,
// and leaves nothing behind: no store (not even one that would not open) and no temporary file.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "common/file_size_limit.h"
#include "common/list_names.h"
#include "common/run_nave.h"
#include "preprocess/preprocess.h"
#include "src/core/memory.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;

// RunPreprocess(o) with files limited to `limit` bytes: its error, or Ok.
Status RunWithFileSizeLimit(const PreprocessOptions& o, rlim_t limit) {
    test::ScopedFileSizeLimit scoped(limit);
    EXPECT_TRUE(scoped.ok()) << "cannot set RLIMIT_FSIZE";
    StatusOr<PreprocessStats> stats = RunPreprocess(o);
    return stats.ok() ? Status::Ok() : stats.status();
}

// A 32 x 32 grid of quads whose 2048 triangles each have their own material, as CAD exports often
// name one per part: the store is mostly its material table, larger than the temporary bins.
void WriteManyMaterialGrid(const std::filesystem::path& dir) {
    constexpr int kSide = 32;
    std::ofstream mtl(dir / "grid.mtl");
    for (int i = 0; i < 2 * kSide * kSide; ++i) mtl << "newmtl part_" << i << "\nKd 0.5 0.5 0.5\n";
    std::ofstream obj(dir / "grid.obj");
    obj << "mtllib grid.mtl\n";
    for (int y = 0; y <= kSide; ++y) {
        for (int x = 0; x <= kSide; ++x) obj << "v " << x << " " << y << " 0\n";
    }
    int material = 0;
    for (int y = 0; y < kSide; ++y) {
        for (int x = 0; x < kSide; ++x) {
            const int a = y * (kSide + 1) + x + 1, b = a + 1, c = a + kSide + 1, d = c + 1;
            obj << "usemtl part_" << material++ << "\nf " << a << " " << b << " " << d << "\n";
            obj << "usemtl part_" << material++ << "\nf " << a << " " << d << " " << c << "\n";
        }
    }
}

// (a) The temporary bins hit the limit: the message names the directory the temporaries go to and
// the option that moves them, whether it is --temp-dir or (by default) the output's directory.
TEST(PreprocessFullDisk, TemporaryBinWriteNamesTheTempDirAndLeavesNothing) {
    const auto out_dir = testing::MakeTempDir("full_bins_out");
    const auto temp_dir = testing::MakeTempDir("full_bins_temp");
    for (bool beside_output : {false, true}) {
        SCOPED_TRACE(beside_output ? "temporaries beside the output" : "--temp-dir");
        PreprocessOptions o;
        o.generate = "abbey:detail=0.01";  // 78 k triangles: bins of megabytes
        o.output = out_dir / "abbey.nave";
        o.temp_dir = beside_output ? std::filesystem::path() : temp_dir;
        o.convert_textures = false;
        o.threads = 2;
        const Status s = RunWithFileSizeLimit(o, 64 << 10);
        ASSERT_FALSE(s.ok());
        EXPECT_EQ(s.code(), StatusCode::kIoError) << s.ToString();
        const std::string where = beside_output ? out_dir.string() : temp_dir.string();
        EXPECT_THAT(s.message(), HasSubstr("writing temporary files in " + where + " "));
        EXPECT_THAT(s.message(), HasSubstr("--temp-dir"));
        EXPECT_THAT(s.message(), HasSubstr(where + "/.nave-tmp-"));  // the bin itself
        EXPECT_THAT(s.message(), HasSubstr(std::strerror(EFBIG)));
        EXPECT_FALSE(std::filesystem::exists(o.output));
        EXPECT_THAT(test::ListNames(out_dir), IsEmpty());
        EXPECT_THAT(test::ListNames(temp_dir), IsEmpty());
    }
    std::filesystem::remove_all(out_dir);
    std::filesystem::remove_all(temp_dir);
}

// (b) Only the store hits the limit: limits between the largest temporary file (at most the peak
// the summary reports) and the store's size, measured by a run without a limit. The message names
// the store's temporary file and the store; no file is left at the output path or beside it.
TEST(PreprocessFullDisk, StoreWriteNamesTheStoreAndLeavesNoFile) {
    const auto src_dir = testing::MakeTempDir("full_store_src");
    const auto out_dir = testing::MakeTempDir("full_store_out");
    WriteManyMaterialGrid(src_dir);
    PreprocessOptions o;
    o.inputs = {src_dir / "grid.obj"};
    o.output = out_dir / "grid.nave";
    o.threads = 2;
    StatusOr<PreprocessStats> measured = RunPreprocess(o);
    ASSERT_TRUE(measured.ok()) << measured.status().ToString();
    const uint64_t temp_bytes = measured->peak_temp_bytes, store_bytes = measured->output_bytes;
    EXPECT_EQ(std::filesystem::file_size(o.output), store_bytes);
    EXPECT_THAT(FormatSummary(*measured),
                HasSubstr("temporary files peaked at " + FormatBytes(temp_bytes)));
    ASSERT_GT(temp_bytes, 0u);
    ASSERT_LT(temp_bytes + 1024, store_bytes) << "the store must outgrow every temporary file";
    std::filesystem::remove(o.output);

    for (uint64_t limit : {temp_bytes + 1024, (temp_bytes + store_bytes) / 2, store_bytes - 1}) {
        SCOPED_TRACE("limit " + std::to_string(limit) + " bytes, store " +
                     std::to_string(store_bytes) + ", temporaries " + std::to_string(temp_bytes));
        const Status s = RunWithFileSizeLimit(o, limit);
        ASSERT_FALSE(s.ok());
        EXPECT_EQ(s.code(), StatusCode::kIoError) << s.ToString();
        EXPECT_THAT(s.message(), HasSubstr(o.output.string() + ".tmp-"));
        EXPECT_THAT(s.message(), HasSubstr("temporary file for " + o.output.string()));
        EXPECT_THAT(s.message(), HasSubstr(std::strerror(EFBIG)));
        EXPECT_THAT(s.message(), Not(HasSubstr("writing temporary files")));  // not the bins
        EXPECT_FALSE(std::filesystem::exists(o.output));
        EXPECT_THAT(test::ListNames(out_dir), IsEmpty());
    }
    // The same run completes once there is room.
    ASSERT_TRUE(RunWithFileSizeLimit(o, store_bytes).ok());
    EXPECT_EQ(std::filesystem::file_size(o.output), store_bytes);
    std::filesystem::remove_all(src_dir);
    std::filesystem::remove_all(out_dir);
}

// (a) as a user sees it: `nave preprocess` exits with 1 and says where the temporaries were going
// and how to move them.
TEST(PreprocessFullDisk, CliReportsTheTempDirAndExitsNonZero) {
    const auto out_dir = testing::MakeTempDir("full_cli_out");
    const auto temp_dir = testing::MakeTempDir("full_cli_temp");
    const auto out = out_dir / "abbey.nave";
    test::CommandResult r;
    {
        test::ScopedFileSizeLimit limit(64 << 10);  // inherited by nave
        ASSERT_TRUE(limit.ok());
        r = test::RunNave("preprocess --generate abbey:detail=0.01 --no-textures --threads 2 -o " +
                          out.string() + " --temp-dir " + temp_dir.string());
    }
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_THAT(r.output, HasSubstr("writing temporary files in " + temp_dir.string() +
                                    " (--temp-dir chooses where)"));
    EXPECT_THAT(r.output, HasSubstr(std::strerror(EFBIG)));
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_THAT(test::ListNames(out_dir), IsEmpty());
    EXPECT_THAT(test::ListNames(temp_dir), IsEmpty());
    std::filesystem::remove_all(out_dir);
    std::filesystem::remove_all(temp_dir);
}

}  // namespace
}  // namespace nave::preprocess
