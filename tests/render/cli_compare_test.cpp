// End-to-end: `nave compare` as users type it, on small images whose error is known: a render
// too bright in one region of nine against its reference shows the bias in that region's mean,
// the relMSE on RGB is the region's share, and a blur keeps most of an error that spans many
// pixels.

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "common/run_nave.h"
#include "common/scratch_dir.h"
#include "src/imaging/image_io.h"

namespace nave::render {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::RunNave;

constexpr int kSize = 12;  // a 3 x 3 grid of 4 x 4 regions

/// A grey image (value 1 in R, G and B) whose top-left 4 x 4 region holds `top_left`.
void WriteGrey(const std::string& path, float top_left) {
    imaging::FloatImage image;
    image.width = kSize;
    image.height = kSize;
    image.channels = {"R", "G", "B"};
    image.pixels.assign(size_t(kSize) * kSize * 3, 1.f);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) {
            for (int c = 0; c < 3; ++c) image.pixels[(size_t(y) * kSize + x) * 3 + c] = top_left;
        }
    }
    ASSERT_TRUE(imaging::WriteExr(path, image, {}).ok());
}

/// The number after `"key": ` in `json`.
double JsonNumber(const std::string& json, const std::string& key) {
    const size_t at = json.find("\"" + key + "\": ");
    EXPECT_NE(at, std::string::npos) << key << " in " << json;
    if (at == std::string::npos) return -1;
    return std::stod(json.substr(at + key.size() + 4));
}

TEST(CliCompareTest, ABiasInOneRegionShowsInItsMeanAndInTheRgbError) {
    test::ScratchDir dir("cli_compare");
    const std::string render = (dir.path() / "render.exr").string();
    const std::string reference = (dir.path() / "reference.exr").string();
    WriteGrey(render, 2.f);
    WriteGrey(reference, 1.f);
    const CommandResult json =
        RunNave("compare " + render + " " + reference + " --reference --json");
    ASSERT_EQ(json.exit_code, 0) << json.output;
    // 16 of 144 pixels off by 1, each against 1 + 0.01 (the mean reference's offset, squared).
    const double expected = 16.0 / 144.0 / 1.01;
    EXPECT_NEAR(JsonNumber(json.output, "relmse_against_reference_rgb"), expected, 1e-5);
    EXPECT_NEAR(JsonNumber(json.output, "relmse_against_reference"), expected, 1e-5);
    // The blur spreads the step over its neighbours: smaller, but far from gone (pixel noise would
    // fall some 80-fold).
    const double blurred = JsonNumber(json.output, "relmse_against_reference_rgb_blurred");
    EXPECT_GT(blurred, 0.2 * expected);
    EXPECT_LT(blurred, expected);
    EXPECT_EQ(JsonNumber(json.output, "rgb_blur_radius"), 4);
    EXPECT_NE(json.output.find("\"region_mean_luminance\": [[2, 1], [1, 1], [1, 1], [1, 1], "
                               "[1, 1], [1, 1], [1, 1], [1, 1], [1, 1]]"),
              std::string::npos)
        << json.output;

    // The terminal's view: the reference over the render, region by region.
    const CommandResult text = RunNave("compare " + render + " " + reference + " --reference");
    ASSERT_EQ(text.exit_code, 0) << text.output;
    EXPECT_NE(text.output.find("mean luminance by region (3 x 3, top row first), second / first:\n"
                               "    0.5000   1.0000   1.0000\n"),
              std::string::npos)
        << text.output;
    EXPECT_NE(text.output.find("RGB box-blurred over 4 pixels"), std::string::npos) << text.output;
}

TEST(CliCompareTest, TwoEqualRendersHaveNoError) {
    test::ScratchDir dir("cli_compare");
    const std::string a = (dir.path() / "a.exr").string(), b = (dir.path() / "b.exr").string();
    WriteGrey(a, 3.f);
    WriteGrey(b, 3.f);
    const CommandResult json = RunNave("compare " + a + " " + b + " --json --blur 2");
    ASSERT_EQ(json.exit_code, 0) << json.output;
    EXPECT_EQ(JsonNumber(json.output, "relmse_of_one"), 0);
    EXPECT_EQ(JsonNumber(json.output, "relmse_of_one_rgb"), 0);
    EXPECT_EQ(JsonNumber(json.output, "relmse_of_one_rgb_blurred"), 0);
    EXPECT_EQ(JsonNumber(json.output, "rgb_blur_radius"), 2);  // --blur chooses it
}

}  // namespace
}  // namespace nave::render
