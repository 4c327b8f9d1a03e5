// End-to-end: a disk that fills while `nave render` writes its image or its checkpoint. The error
// names the file and exits 1; the image a previous render left there is untouched and no partial
// file stays behind. (A full disk while spilling ray queues: pager_test.cpp.)

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "common/file_size_limit.h"
#include "common/list_names.h"
#include "common/run_nave.h"
#include "common/scratch_dir.h"

namespace nave::render {
namespace {

const std::string kFurnaceConfig =
    std::string(NAVE_TEST_FIXTURES) + "/../../configs/test_furnace.toml";

std::string Contents(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(CliFullDisk, ImageWriteNamesTheImageAndKeepsThePreviousOne) {
    const test::ScratchDir dir("render_full_disk");
    const auto out = dir / "furnace.exr";
    const std::string render = "render --procedural furnace --config " + kFurnaceConfig +
                               " --resolution 96x64 --spp 1 --threads 1 -o " + out.string();
    const test::CommandResult first = test::RunNave(render);
    ASSERT_EQ(first.exit_code, 0) << first.output;
    const std::string before = Contents(out);
    ASSERT_GT(before.size(), 4096u);
    test::CommandResult r;
    {
        // The image is larger than 4 KiB: its write fails as on a full disk.
        test::ScopedFileSizeLimit limit(4 << 10);
        ASSERT_TRUE(limit.ok());
        r = test::RunNave(render + " --seed 7");
    }
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(out.string()), std::string::npos) << r.output;
    EXPECT_EQ(Contents(out), before) << "the previous image changed";
    EXPECT_EQ(test::ListNames(dir.path()),
              (std::vector<std::string>{"furnace.exr", "furnace.png"}));
}

TEST(CliFullDisk, CheckpointWriteNamesTheCheckpoint) {
    const test::ScratchDir dir("render_full_disk_checkpoint");
    const auto out = dir / "furnace.exr";
    const auto checkpoint = dir / "furnace.ckpt";
    test::CommandResult r;
    {
        // The film alone (96x64 pixels of double sums) is far over 4 KiB.
        test::ScopedFileSizeLimit limit(4 << 10);
        ASSERT_TRUE(limit.ok());
        r = test::RunNave("render --procedural furnace --config " + kFurnaceConfig +
                          " --resolution 96x64 --spp 2 --threads 1 --checkpoint " +
                          checkpoint.string() + " --stop-after 1 -o " + out.string());
    }
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find(checkpoint.string()), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(checkpoint));
    for (const std::string& name : test::ListNames(dir.path()))
        EXPECT_EQ(name.find(".tmp"), std::string::npos) << "left behind: " << name;
}

}  // namespace
}  // namespace nave::render
