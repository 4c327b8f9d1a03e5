// End-to-end: `nave render` as the user runs it (NAVE_BINARY): outputs, metadata, error messages, exit codes.

#include <gtest/gtest.h>

#include "common/run_nave.h"
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "imaging/image_io.h"

namespace nave::render {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::RunNave;


class CliRenderTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() / ("nave_cli_render_" + std::to_string(getpid()));
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path Write(const std::string& name, const std::string& text) {
        std::ofstream(dir_ / name) << text;
        return dir_ / name;
    }
    std::filesystem::path dir_;
};

TEST_F(CliRenderTest, RendersExrAndPngWithMetadata) {
    auto config = Write("furnace.toml", R"(
[camera]
position = [0.1, 0.05, 0.0]
look_at = [1, 0.2, 0.1]
fov_deg = 90
resolution = [16, 12]
[materials.shell]
reflectance = 0.5
emission = 0.5
[render]
spp = 8
max_depth = 32
[output]
aovs = ["albedo", "normal", "depth"]
)");
    auto out = dir_ / "furnace.exr";
    CommandResult r = RunNave("-q render --procedural furnace:bricks=2 --config " + config.string() + " -o " +
                              out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    ASSERT_TRUE(std::filesystem::exists(out));
    ASSERT_TRUE(std::filesystem::exists(dir_ / "furnace.png"));
    auto image = imaging::ReadImage(out);
    ASSERT_TRUE(image.ok()) << image.status().ToString();
    EXPECT_EQ(image->width, 16);
    EXPECT_EQ(image->height, 12);
    ASSERT_EQ(image->channels.size(), 10u);  // RGB, albedo RGB, normal XYZ, Z (in the file's order)
    auto z = std::find(image->channels.begin(), image->channels.end(), "Z");
    ASSERT_NE(z, image->channels.end());
    // Depth inside a unit sphere seen from near its centre: about 1 m.
    EXPECT_NEAR(image->pixels[size_t(z - image->channels.begin())], 1.0, 0.15);
    // No temporary files are left behind.
    int files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_)) {
        (void)e;
        ++files;
    }
    EXPECT_EQ(files, 3);  // furnace.toml, furnace.exr, furnace.png
}

TEST_F(CliRenderTest, ConfigErrorsNameFileLineAndKeyWithExitCode2) {
    auto config = Write("bad.toml", "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[render]\nsp = 4\n");
    CommandResult r = RunNave("render --procedural furnace --config " + config.string() + " -o " +
                              (dir_ / "x.exr").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("bad.toml:5:1"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("render.sp"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "x.exr"));
}

TEST_F(CliRenderTest, MissingMaterialMappingAndMissingModel) {
    auto config = Write("c.toml", "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[materials.stone]\n");
    CommandResult r = RunNave("render --procedural furnace --config " + config.string() + " -o " +
                              (dir_ / "x.exr").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("'shell' has no mapping"), std::string::npos) << r.output;
    CommandResult m = RunNave("render " + (dir_ / "nowhere.nave").string() + " --config " + config.string() +
                              " -o " + (dir_ / "x.exr").string());
    EXPECT_NE(m.exit_code, 0);
    EXPECT_NE(m.output.find("nowhere.nave"), std::string::npos) << m.output;
}

}  // namespace
}  // namespace nave::render
