// RGB -> spectrum uplift (Jakob & Hanika 2019): round trips through the CIE observer, bounds,
// greys, emission.

#include "src/core/rgb_to_spectrum.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>

#include "src/core/color.h"
#include "src/core/illuminant.h"

namespace nave {
namespace {

// The 8-bit sRGB triples of the 24 ColorChecker patches as BabelColor prints them beside its
// average CIELAB (D. Pascale, "RGB coordinates of the Macbeth ColorChecker", BabelColor 2006; the
// same triples are in tests/core/colorchecker_test.cpp and Wikipedia's "ColorChecker"). Here they
// are only used as 24 realistic in-gamut sRGB colours to lift.
constexpr std::array<std::array<int, 3>, 24> kColorCheckerSrgb8 = {{
    {115, 82, 68},   {194, 150, 130}, {98, 122, 157}, {87, 108, 67},   {133, 128, 177},
    {103, 189, 170}, {214, 126, 44},  {80, 91, 166},  {193, 90, 99},   {94, 60, 108},
    {157, 188, 64},  {224, 163, 46},  {56, 61, 150},  {70, 148, 73},   {175, 54, 60},
    {231, 199, 31},  {187, 86, 149},  {8, 133, 161},  {243, 243, 242}, {200, 200, 200},
    {160, 160, 160}, {122, 122, 121}, {85, 85, 85},   {52, 52, 52},
}};

Vec3f DecodeSrgb8(const std::array<int, 3>& c) {
    return Vec3f(float(SrgbDecode(c[0] / 255.0)), float(SrgbDecode(c[1] / 255.0)),
                 float(SrgbDecode(c[2] / 255.0)));
}

// The sRGB colour of a reflectance under the space's own white (D65): CIE 15:2004 eqs. 7.1-7.3
// with the 1 nm CIE 1931 tables, then the IEC 61966-2-1 matrix. No adaptation: the white is the
// space's white.
double RoundTripDeltaE(const Vec3f& rgb) {
    const RgbColorSpace& srgb = RgbColorSpace::Srgb();
    Spectrum refl = UpliftReflectance(rgb).ToSpectrum();
    Vec3d xyz = ReflectanceToXYZ(refl, IlluminantD65());
    Vec3d white = ReflectanceToXYZ(Spectrum::Constant(1.f), IlluminantD65());
    Vec3d target = srgb.ToXyz(Vec3d(rgb));
    return DeltaE76(XYZToLab(xyz, white), XYZToLab(target, white));
}

TEST(RgbToSpectrumTest, TableSolvesEveryNodeOfTheSrgbGamut) {
    auto start = std::chrono::steady_clock::now();
    const RgbToSpectrumTable& table = RgbToSpectrumTable::For(RgbColorSpace::Srgb());
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    RecordProperty("table_seconds", std::to_string(seconds));
    std::printf("sRGB table: %.3f s, max node dE %.4f\n", seconds, table.max_node_delta_e());
    // Every node of the sRGB cube is reachable by a sigmoid polynomial (paper §5, Fig. 6: the
    // space covers sRGB); the solver reaches each within a small ΔE*ab.
    EXPECT_LT(table.max_node_delta_e(), 0.5);
    EXPECT_EQ(&table, &RgbToSpectrumTable::For(RgbColorSpace::Srgb()));
}

TEST(RgbToSpectrumTest, ColorCheckerRoundTripsWithinDeltaE1) {
    for (size_t i = 0; i < kColorCheckerSrgb8.size(); ++i) {
        Vec3f rgb = DecodeSrgb8(kColorCheckerSrgb8[i]);
        EXPECT_LT(RoundTripDeltaE(rgb), 1.0) << "patch " << i;
        SigmoidPolynomial s = UpliftReflectance(rgb);
        EXPECT_LE(s.MaxValue(), 1.f) << "patch " << i;
        EXPECT_GE(s.Evaluate(kLambdaMinNm), 0.f);
    }
}

TEST(RgbToSpectrumTest, RandomInGamutColoursRoundTrip) {
    // Interpolation between table nodes is the only error left; checked on colours away from the
    // cube's faces (where a component is 0 the reflectance must reach 0, only asymptotically).
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.02f, 0.98f);
    double worst = 0;
    for (int i = 0; i < 300; ++i) {
        Vec3f rgb(u(rng), u(rng), u(rng));
        double de = RoundTripDeltaE(rgb);
        worst = std::max(worst, de);
        EXPECT_LT(de, 1.0) << rgb.x << " " << rgb.y << " " << rgb.z;
    }
    RecordProperty("worst_delta_e", std::to_string(worst));
    std::printf("worst round-trip dE76 over 300 colours: %.4f\n", worst);
}

TEST(RgbToSpectrumTest, ReflectanceNeverExceedsOne) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int i = 0; i < 2000; ++i) {
        // Including out-of-range inputs, which are clamped.
        Vec3f rgb(2.f * u(rng) - 0.25f, u(rng), 1.5f * u(rng));
        SigmoidPolynomial s = UpliftReflectance(rgb);
        Spectrum t = s.ToSpectrum();
        EXPECT_LE(t.MaxValue(), 1.f);
        EXPECT_LE(s.MaxValue(), 1.f);
        EXPECT_NEAR(s.MaxValue(), t.MaxValue(), 1e-3f);
    }
}

TEST(RgbToSpectrumTest, GreysAreFlat) {
    Spectrum white = UpliftReflectance(Vec3f(1.f, 1.f, 1.f)).ToSpectrum();
    Spectrum black = UpliftReflectance(Vec3f(0.f, 0.f, 0.f)).ToSpectrum();
    for (int i = 0; i < Spectrum::kNumSamples; ++i) {
        EXPECT_EQ(white.sample(i), 1.f);
        EXPECT_EQ(black.sample(i), 0.f);
    }
    for (float v : {0.01f, 0.18f, 0.5f, 0.9f}) {
        SigmoidPolynomial s = UpliftReflectance(Vec3f(v, v, v));
        EXPECT_NEAR(s.Evaluate(400.f), v, 1e-6f);
        EXPECT_NEAR(s.Evaluate(700.f), v, 1e-6f);
    }
}

TEST(RgbToSpectrumTest, SaturatedPrimariesKeepTheirHue) {
    // A lifted red reflects most at long wavelengths, a blue at short ones.
    SigmoidPolynomial red = UpliftReflectance(Vec3f(0.8f, 0.05f, 0.05f));
    SigmoidPolynomial blue = UpliftReflectance(Vec3f(0.05f, 0.05f, 0.8f));
    EXPECT_GT(red.Evaluate(650.f), 0.7f);
    EXPECT_LT(red.Evaluate(450.f), 0.1f);
    EXPECT_GT(blue.Evaluate(450.f), 0.7f);
    EXPECT_LT(blue.Evaluate(650.f), 0.1f);
}

TEST(RgbToSpectrumTest, EmissionReproducesItsRgb) {
    const RgbColorSpace& srgb = RgbColorSpace::Srgb();
    for (Vec3f rgb : {Vec3f(1.f, 1.f, 1.f), Vec3f(5.f, 2.f, 0.5f), Vec3f(0.1f, 0.3f, 12.f)}) {
        Vec3d back = srgb.ToRgb(SpectrumToXYZ(RgbEmission(rgb).ToSpectrum()));
        float m = std::max({rgb.x, rgb.y, rgb.z});
        EXPECT_NEAR(back.x, rgb.x, 0.01 * m);
        EXPECT_NEAR(back.y, rgb.y, 0.01 * m);
        EXPECT_NEAR(back.z, rgb.z, 0.01 * m);
    }
    // The white of the space is its illuminant.
    EXPECT_NEAR(RgbEmission(Vec3f(1.f, 1.f, 1.f)).Evaluate(560.f),
                RgbToSpectrumTable::For(srgb).illuminant()(560.f), 1e-6f);
    EXPECT_EQ(RgbEmission(Vec3f(0.f, 0.f, 0.f)).Evaluate(550.f), 0.f);
}

}  // namespace
}  // namespace nave
