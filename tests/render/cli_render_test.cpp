// End-to-end: `nave render` as the user runs it (NAVE_BINARY): outputs, metadata, error messages,
// exit codes.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/list_names.h"
#include "common/run_nave.h"
#include "src/core/file.h"
#include "src/imaging/image_io.h"

namespace nave::render {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::RunNave;

class CliRenderTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_cli_render_" + std::to_string(getpid()));
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path Write(const std::string& name, const std::string& text) {
        std::ofstream(dir_ / name) << text;
        return dir_ / name;
    }
    std::filesystem::path dir_;
};

// The whole texture path as a user runs it: an OBJ whose MTL names an sRGB checkerboard (map_Kd)
// and a mask (map_d) is preprocessed (textures converted beside the store) and rendered over a
// uniform sky. The masked-out left half shows the sky; the right half shows the checker's colours
// where its texels are.
TEST_F(CliRenderTest, PreprocessedTexturesAppearInTheRender) {
    // 2 x 2 checker, 8-bit sRGB: top-left and bottom-right red, the others blue. Mask 2 x 1: left
    // 0, right 255.
    const std::vector<uint8_t> checker = {200, 10, 10, 10, 10, 200, 10, 10, 200, 200, 10, 10};
    ASSERT_TRUE(imaging::WriteRgb8(dir_ / "checker.png", 2, 2, checker, {}).ok());
    ASSERT_TRUE(imaging::WriteRgb8(dir_ / "mask.png", 2, 1, {0, 0, 0, 255, 255, 255}, {}).ok());
    Write("quad.mtl", "newmtl painted\nKd 0.5 0.5 0.5\nmap_Kd checker.png\nmap_d mask.png\n");
    Write("quad.obj",
          "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl painted\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
    CommandResult pre =
        RunNave("preprocess " + (dir_ / "quad.obj").string() + " -o " + (dir_ / "q.nave").string());
    ASSERT_EQ(pre.exit_code, 0) << pre.output;
    int converted = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_ / "q.nave.textures"))
        converted += e.is_regular_file();
    EXPECT_EQ(converted, 2) << "one colour texture and one data texture";

    const auto config = std::filesystem::path(NAVE_TEST_FIXTURES) / "scenes/quad_under_sky.toml";
    auto out = dir_ / "quad.exr";
    CommandResult r = RunNave("render " + (dir_ / "q.nave").string() + " -c " + config.string() +
                              " -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("textures: read"), std::string::npos) << r.output;
    auto image = imaging::ReadImage(out);
    ASSERT_TRUE(image.ok()) << image.status().ToString();
    ASSERT_GE(image->channels.size(), 3u);
    // The mean of the 3 x 3 pixels around (x, y): single pixels carry the colour noise of 16
    // spectral samples.
    auto rgb = [&](int x, int y) {
        std::array<float, 3> sum{};
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const size_t i = (size_t(y + dy) * 32 + size_t(x + dx)) * image->channels.size();
                for (int c = 0; c < 3; ++c) sum[size_t(c)] += image->pixels[i + size_t(c)] / 9;
            }
        return sum;
    };
    auto blue = rgb(26, 5), red = rgb(26, 26), sky = rgb(5, 16);
    EXPECT_GT(blue[2], 4 * blue[0]) << blue[0] << " " << blue[2];
    EXPECT_GT(red[0], 4 * red[2]) << red[0] << " " << red[2];
    // The sky (radiance 1) seen through the cut-out half: brighter than any lit texel (albedo <=
    // 0.6) and grey.
    EXPECT_GT(sky[1], 0.8f);
    EXPECT_GT(sky[2], 0.6f * sky[0]);

    // Under --memory the texture cache gets [textures] memory_share of the budget (1 % of 400 MiB
    // here, below what the two tiny textures would use), counted as reserved.
    const std::string shared_config =
        ReadFileToString(config).value() + "[textures]\nmemory_share = 0.01\n";
    const auto share = Write("share.toml", shared_config);
    CommandResult budget = RunNave("render " + (dir_ / "q.nave").string() + " -c " +
                                   share.string() + " -o " + out.string() + " --memory 400M");
    ASSERT_EQ(budget.exit_code, 0) << budget.output;
    EXPECT_NE(budget.output.find("of which 4.0 MiB for the texture cache"), std::string::npos)
        << budget.output;
    EXPECT_NE(budget.output.find("through a 4.0 MiB tile cache"), std::string::npos)
        << budget.output;

    // --no-textures: the flat grey material everywhere, the quad whole.
    CommandResult flat = RunNave("render " + (dir_ / "q.nave").string() + " -c " + config.string() +
                                 " -o " + out.string() + " --no-textures");
    ASSERT_EQ(flat.exit_code, 0) << flat.output;
    image = imaging::ReadImage(out);
    ASSERT_TRUE(image.ok());
    auto grey = rgb(26, 5), left = rgb(5, 16);
    EXPECT_NEAR(grey[0] / grey[2], left[0] / left[2], 0.15);
    EXPECT_LT(left[1], 0.7f) << "the grey quad, not the sky";
}

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
    CommandResult r = RunNave("-q render --procedural furnace:bricks=2 --config " +
                              config.string() + " -o " + out.string());
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
    EXPECT_EQ(test::ListNames(dir_),
              (std::vector<std::string>{"furnace.exr", "furnace.png", "furnace.toml"}));
}

TEST_F(CliRenderTest, ConfigErrorsNameFileLineAndKeyWithExitCode2) {
    auto config =
        Write("bad.toml", "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[render]\nsp = 4\n");
    CommandResult r = RunNave("render --procedural furnace --config " + config.string() + " -o " +
                              (dir_ / "x.exr").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("bad.toml:5:1"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("render.sp"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "x.exr"));
}

TEST_F(CliRenderTest, MissingMaterialMappingAndMissingModel) {
    auto config =
        Write("c.toml", "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[materials.stone]\n");
    CommandResult r = RunNave("render --procedural furnace --config " + config.string() + " -o " +
                              (dir_ / "x.exr").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("'shell' has no mapping"), std::string::npos) << r.output;
    CommandResult m = RunNave("render " + (dir_ / "nowhere.nave").string() + " --config " +
                              config.string() + " -o " + (dir_ / "x.exr").string());
    EXPECT_NE(m.exit_code, 0);
    EXPECT_NE(m.output.find("nowhere.nave"), std::string::npos) << m.output;
}

}  // namespace
}  // namespace nave::render
