// Colorimetry against published values; each test names its source.

#include "src/core/color.h"

#include <gtest/gtest.h>

#include "src/core/illuminant.h"

namespace nave {
namespace {

// CIE 018:2019 1 nm CMF table: Σȳ over 360-830 nm = 106.856895 (the constant pbrt-v4 uses as
// CIE_Y_integral). The CSV's 7-significant-digit rounding moves the sum by 2e-5.
TEST(ColorTest, CieYIntegral) {
    EXPECT_NEAR(CieYIntegral(), kCieYIntegralPublished, 5e-5);
    EXPECT_FLOAT_EQ(CieY().Evaluate(555.f), 1.f);
    EXPECT_NEAR(CieX().Evaluate(600.f), 1.0622f, 1e-6f);
    EXPECT_NEAR(CieZ().Evaluate(450.f), 1.77211f, 1e-6f);
}

// IEC 61966-2-1:1999 (amendment 1, 2003) eq. (F.8): the XYZ -> linear sRGB matrix to 4 decimals.
TEST(ColorTest, SrgbMatrixFromPrimaries) {
    const double expected[3][3] = {
        {3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}};
    const Mat3d& m = RgbColorSpace::Srgb().xyz_to_rgb();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(m(i, j), expected[i][j], 1e-3) << i << "," << j;
    Vec3d white = RgbColorSpace::Srgb().ToXyz({1, 1, 1});
    EXPECT_NEAR(white.x, 0.9505, 1e-4);
    EXPECT_NEAR(white.y, 1.0, 1e-12);
    EXPECT_NEAR(white.z, 1.0891, 1e-4);
}

// ITU-R BT.2020 / ACEScg: RGB->XYZ matrices as published (BT.2087-0 Annex 1 eq. for BT.2020
// normalised primary matrix; Academy S-2014-004 §4.1.2 for AP1).
TEST(ColorTest, Rec2020AndAcesCgMatrices) {
    const Mat3d& r = RgbColorSpace::Rec2020().rgb_to_xyz();
    EXPECT_NEAR(r(0, 0), 0.6370, 1e-4);
    EXPECT_NEAR(r(0, 1), 0.1446, 1e-4);
    EXPECT_NEAR(r(0, 2), 0.1689, 1e-4);
    EXPECT_NEAR(r(1, 0), 0.2627, 1e-4);
    EXPECT_NEAR(r(1, 1), 0.6780, 1e-4);
    EXPECT_NEAR(r(1, 2), 0.0593, 1e-4);
    const Mat3d& a = RgbColorSpace::AcesCg().rgb_to_xyz();
    EXPECT_NEAR(a(0, 0), 0.6624541811, 1e-6);
    EXPECT_NEAR(a(0, 1), 0.1340042065, 1e-6);
    EXPECT_NEAR(a(1, 0), 0.2722287168, 1e-6);
    EXPECT_NEAR(a(1, 1), 0.6740817658, 1e-6);
    EXPECT_NEAR(a(2, 2), 1.0103391003, 1e-6);
}

// D65 white is sRGB's white: (1, 1, 1) within 1 %.
TEST(ColorTest, D65IsSrgbWhite) {
    Vec3d xyz = SpectrumToXYZ(IlluminantD65());
    Vec3d rgb = RgbColorSpace::Srgb().ToRgb(xyz / xyz.y);
    EXPECT_NEAR(rgb.x, 1.0, 0.01);
    EXPECT_NEAR(rgb.y, 1.0, 0.01);
    EXPECT_NEAR(rgb.z, 1.0, 0.01);
}

// CIE 15:2004 Table T.3: chromaticities of the standard illuminants, 2° observer.
TEST(ColorTest, IlluminantChromaticities) {
    Chromaticity d65 = IlluminantChromaticity(IlluminantD65());
    EXPECT_NEAR(d65.x, 0.31272, 1e-4);
    EXPECT_NEAR(d65.y, 0.32903, 1e-4);
    Chromaticity a = IlluminantChromaticity(IlluminantA());
    EXPECT_NEAR(a.x, 0.44757, 1e-4);
    EXPECT_NEAR(a.y, 0.40745, 1e-4);
    Chromaticity d50 = IlluminantChromaticity(IlluminantD50());
    EXPECT_NEAR(d50.x, 0.34567, 2e-4);
    EXPECT_NEAR(d50.y, 0.35850, 2e-4);
    Chromaticity d55 = IlluminantChromaticity(NamedIlluminant("D55").value());
    EXPECT_NEAR(d55.x, 0.33242, 2e-4);
    EXPECT_NEAR(d55.y, 0.34743, 2e-4);
}

TEST(ColorTest, NamedIlluminants) {
    EXPECT_TRUE(NamedIlluminant("d65").ok());
    EXPECT_TRUE(NamedIlluminant("A").ok());
    EXPECT_TRUE(NamedIlluminant("D:5000").ok());
    EXPECT_TRUE(NamedIlluminant("blackbody:3000").ok());
    StatusOr<Spectrum> bad = NamedIlluminant("F11");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(bad.status().message().find("F11"), std::string::npos);
    EXPECT_FALSE(NamedIlluminant("D:90000").ok());
    EXPECT_FALSE(NamedIlluminant("blackbody:-5").ok());
}

// McCamy (1992): 2856 K for illuminant A and 6504 K for D65, within a few kelvin.
TEST(ColorTest, McCamyCct) {
    EXPECT_NEAR(CctMcCamy(IlluminantChromaticity(IlluminantA())), 2856.0, 3.0);
    EXPECT_NEAR(CctMcCamy(IlluminantChromaticity(IlluminantD65())), 6504.0, 5.0);
    // A black body at 4000 K lies on the locus; the cubic is within ~10 K there.
    EXPECT_NEAR(CctMcCamy(IlluminantChromaticity(Spectrum::Blackbody(4000.0))), 4000.0, 15.0);
}

// Robertson (1968) with the Wyszecki & Stiles isotemperature lines: black bodies give back their
// own temperature (0.2 %), illuminant A 2856 K, D65 6504 K; and the table's (u, v) lie on the
// Planckian locus computed from nave's CMFs (a check of both tables).
TEST(ColorTest, RobertsonCct) {
    for (double t : {2000.0, 2856.0, 4000.0, 5000.0, 6500.0, 9000.0, 15000.0})
        EXPECT_NEAR(CctRobertson(IlluminantChromaticity(Spectrum::Blackbody(t))) / t, 1.0, 2e-3)
            << t;
    EXPECT_NEAR(CctRobertson(IlluminantChromaticity(IlluminantA())), 2856.0, 4.0);
    EXPECT_NEAR(CctRobertson(IlluminantChromaticity(IlluminantD65())), 6504.0, 10.0);
    for (double mired : {100.0, 200.0, 300.0, 400.0, 500.0}) {
        Chromaticity c = IlluminantChromaticity(Spectrum::Blackbody(1e6 / mired));
        double den = -2 * c.x + 12 * c.y + 3;
        double u = 4 * c.x / den, v = 6 * c.y / den;
        double tu = mired == 100   ? 0.19032
                    : mired == 200 ? 0.21142
                    : mired == 300 ? 0.24010
                    : mired == 400 ? 0.27218
                                   : 0.30505;
        double tv = mired == 100   ? 0.29326
                    : mired == 200 ? 0.32312
                    : mired == 300 ? 0.34308
                    : mired == 400 ? 0.35407
                                   : 0.35907;
        EXPECT_NEAR(u, tu, 3e-4) << mired;
        EXPECT_NEAR(v, tv, 3e-4) << mired;
    }
}

// Lindbloom's Bradford D65 -> D50 matrix (brucelindbloom.com, "Chromatic Adaptation"), computed
// with whites (0.95047, 1, 1.08883) and (0.96422, 1, 0.82521); our whites come from xy, hence 2e-3.
TEST(ColorTest, BradfordD65ToD50) {
    Mat3d m = ChromaticAdaptationMatrix({0.3127, 0.3290}, {0.3457, 0.3585});
    const double expected[3][3] = {{1.0478112, 0.0228866, -0.0501270},
                                   {0.0295424, 0.9904844, -0.0170491},
                                   {-0.0092345, 0.0150436, 0.7521316}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(m(i, j), expected[i][j], 2e-3) << i << "," << j;
}

// CAT02 (CIE 159:2004) and CAT16 (Li et al. 2017) are normalised to equal-energy white (each row of
// their matrices sums to 1, as published): adapting from E to E is the identity, and between two
// whites they differ from Bradford by a few thousandths on a saturated colour, never by more than
// the methods' own spread (a typo in a coefficient moves them far more). The names parse.
TEST(ColorTest, Cat02AndCat16) {
    for (AdaptationMethod method : {AdaptationMethod::kCat02, AdaptationMethod::kCat16}) {
        Mat3d same = ChromaticAdaptationMatrix({1.0 / 3, 1.0 / 3}, {1.0 / 3, 1.0 / 3}, method);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) EXPECT_NEAR(same(i, j), i == j ? 1.0 : 0.0, 1e-9);
        // Illuminant A to D65, a saturated red: within 0.02 in xy of Bradford.
        const Vec3d red = ChromaticityToXYZ({0.55, 0.32});
        const Chromaticity a = XYZToChromaticity(
            ChromaticAdaptationMatrix({0.4476, 0.4074}, {0.3127, 0.3290}, method) * red);
        const Chromaticity b =
            XYZToChromaticity(ChromaticAdaptationMatrix({0.4476, 0.4074}, {0.3127, 0.3290}) * red);
        EXPECT_NEAR(a.x, b.x, 0.02);
        EXPECT_NEAR(a.y, b.y, 0.02);
        EXPECT_GT(std::abs(a.x - b.x) + std::abs(a.y - b.y), 1e-4) << "a different transform";
    }
    EXPECT_EQ(ParseAdaptationMethod("cat16"), AdaptationMethod::kCat16);
    EXPECT_EQ(ParseAdaptationMethod("von_kries"), AdaptationMethod::kVonKries);
    EXPECT_FALSE(ParseAdaptationMethod("CAT16").has_value());
}

// White balance: a perfect white under illuminant A comes out neutral after balancing to A.
TEST(ColorTest, WhiteBalanceMakesTheIlluminantNeutral) {
    Vec3d xyz = SpectrumToXYZ(IlluminantA());
    Mat3d m = WhiteBalancedXyzToRgb(RgbColorSpace::Srgb(), IlluminantChromaticity(IlluminantA()));
    Vec3d rgb = m * (xyz / xyz.y);
    EXPECT_NEAR(rgb.x, 1.0, 1e-9);
    EXPECT_NEAR(rgb.y, 1.0, 1e-9);
    EXPECT_NEAR(rgb.z, 1.0, 1e-9);
}

// IEC 61966-2-1 transfer curve: known points and a round trip.
TEST(ColorTest, SrgbTransferAnd8Bit) {
    EXPECT_DOUBLE_EQ(SrgbEncode(0.0), 0.0);
    EXPECT_NEAR(SrgbEncode(1.0), 1.0, 1e-12);
    EXPECT_NEAR(SrgbEncode(0.0031308), 0.040449936, 1e-8);
    EXPECT_NEAR(SrgbEncode(0.18), 0.461356, 1e-6);
    for (double v : {0.001, 0.02, 0.2, 0.5, 0.9}) EXPECT_NEAR(SrgbDecode(SrgbEncode(v)), v, 1e-12);
    EXPECT_EQ(LinearSrgbTo8Bit({0.5, 0.0, 2.0}), (std::array<uint8_t, 3>{188, 0, 255}));
    EXPECT_EQ(LinearSrgbTo8Bit({-1.0, 0.2158605, 1.0}), (std::array<uint8_t, 3>{0, 128, 255}));
    Vec3d e = ApplyExposure({1, 2, 3}, -1.0);
    EXPECT_DOUBLE_EQ(e.z, 1.5);
}

// CIE 15:2004 §8.2.1: the white is L* = 100, a* = b* = 0; 18 % grey has L* = 49.5.
TEST(ColorTest, Lab) {
    Vec3d white{0.95047, 1.0, 1.08883};
    Vec3d lab = XYZToLab(white, white);
    EXPECT_NEAR(lab.x, 100.0, 1e-9);
    EXPECT_NEAR(lab.y, 0.0, 1e-9);
    EXPECT_NEAR(lab.z, 0.0, 1e-9);
    EXPECT_NEAR(XYZToLab(white * 0.18, white).x, 49.4961, 1e-3);
    EXPECT_NEAR(XYZToLab(white * 0.001, white).x, 0.9033, 1e-3);  // the linear segment
    EXPECT_DOUBLE_EQ(DeltaE76({50, 3, 4}, {50, 0, 0}), 5.0);
}

}  // namespace
}  // namespace nave
