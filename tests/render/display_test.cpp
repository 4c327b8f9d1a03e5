// The PNG's exposure and tone curve: physical exposure against the photographic standards'
// constants, and a tone curve that keeps saturated colours' hues.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "src/core/color.h"
#include "src/render/film/film.h"

namespace nave::render {
namespace {

/// A film value (linear sRGB, luminance in the film's units) whose luminance is `cd_m2` cd/m².
double FilmLuminance(double cd_m2) { return cd_m2 / (683.002 * CieYIntegral()); }

uint8_t Expected8Bit(double linear) { return LinearSrgbTo8Bit(Vec3d(linear, linear, linear))[0]; }

// A camera at EV100 saturates at L_max = 78 / (q S) 2^EV100 = 1.2 2^EV100 cd/m² (ISO 12232:2006
// saturation-based speed, q = 0.65, S = 100); a reflected-light meter sets EV100 = log2(L S / K)
// with K = 12.5 (ISO 2720:1974), so a uniform scene metered on itself shows at 12.5 / (1.2 * 100) =
// 0.104 of full scale, whatever its luminance.
TEST(DisplayTest, PhysicalExposureFollowsTheStandards) {
    OutputConfig out;
    out.exposure = OutputConfig::Exposure::kPhysical;
    out.ev100 = 10;
    const double l_max = 1.2 * 1024;
    for (double share : {0.05, 0.18, 0.5}) {
        const float y = float(FilmLuminance(share * l_max));
        const std::vector<uint8_t> png = DisplayImage(std::vector<float>(3 * 4, y), out);
        EXPECT_EQ(png[0], Expected8Bit(share)) << share;
    }
    out.ev100.reset();  // metered
    for (double cd : {50.0, 3000.0, 80000.0}) {
        const float y = float(FilmLuminance(cd));
        const std::vector<uint8_t> png = DisplayImage(std::vector<float>(3 * 4, y), out);
        EXPECT_NEAR(png[0], Expected8Bit(12.5 / 120), 1) << cd;
    }
    // Auto exposure maps the log-average to middle grey.
    OutputConfig automatic;
    const std::vector<uint8_t> png = DisplayImage(std::vector<float>(3 * 4, 0.003f), automatic);
    EXPECT_NEAR(png[0], Expected8Bit(0.18), 1);
}

// A bright, saturated glass red (linear 1 : 0.2 : 0.05, twice over full scale): clipping each
// channel turns it orange (G/R 0.4), the hue-preserving curve keeps G/R and B/R.
TEST(DisplayTest, TheHuePreservingCurveKeepsSaturatedColours) {
    OutputConfig out;
    out.exposure = OutputConfig::Exposure::kPhysical;
    out.ev100 = 0;  // L_max = 1.2 cd/m²
    const double scale = FilmLuminance(1.2) * 2;
    const std::vector<float> red = {float(scale), float(0.2 * scale), float(0.05 * scale)};
    auto linear = [](uint8_t v) { return SrgbDecode(v / 255.0); };
    out.tone = OutputConfig::Tone::kClip;
    std::vector<uint8_t> clip = DisplayImage(red, out);
    EXPECT_EQ(clip[0], 255);
    EXPECT_GT(linear(clip[1]) / linear(clip[0]), 0.35);
    out.tone = OutputConfig::Tone::kHuePreserving;
    std::vector<uint8_t> kept = DisplayImage(red, out);
    EXPECT_NEAR(linear(kept[1]) / linear(kept[0]), 0.2, 0.01);
    EXPECT_NEAR(linear(kept[2]) / linear(kept[0]), 0.05, 0.01);
    EXPECT_LT(kept[0], 255);
}

}  // namespace
}  // namespace nave::render
