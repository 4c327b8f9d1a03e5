#pragma once
// Colorimetry: the CIE 1931 2° observer, spectra -> XYZ (exact sums and the film's Monte Carlo
// estimator), RGB colour spaces derived from their primaries, chromatic adaptation, CIELAB, the
// sRGB transfer curve, exposure and 8-bit output, correlated colour temperature.

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"

namespace nave {

/// ∫ȳ(λ)dλ of the CIE 1931 2° 1 nm table over 360-830 nm, as published (CIE 018:2019 data; the
/// value pbrt-v4 uses). CieYIntegral() is the sum of the table nave compiles in, equal to this
/// within 3e-5.
inline constexpr double kCieYIntegralPublished = 106.856895;

/// The CIE 1931 2° colour-matching functions x̄, ȳ, z̄ (1 nm, 360-830 nm, CIE 018:2019 CSV).
const Spectrum& CieX();
const Spectrum& CieY();
const Spectrum& CieZ();
/// Σ ȳ over the 1 nm table (nm), the normaliser of SpectrumToXYZ and SampledToXYZ.
double CieYIntegral();

/// A 3x3 matrix of doubles, row-major, for colour transforms.
struct Mat3d {
    std::array<std::array<double, 3>, 3> m{};

    static Mat3d Identity();
    static Mat3d Diagonal(const Vec3d& d);
    /// The matrix whose columns are a, b, c.
    static Mat3d FromColumns(const Vec3d& a, const Vec3d& b, const Vec3d& c);
    Vec3d operator*(const Vec3d& v) const;
    Mat3d operator*(const Mat3d& o) const;
    double operator()(int r, int c) const { return m[r][c]; }
    /// The inverse; CHECK-fails on a singular matrix (colour-space matrices never are).
    Mat3d Inverse() const;
};
std::ostream& operator<<(std::ostream& os, const Mat3d& m);

/// CIE 1931 chromaticity coordinates.
struct Chromaticity {
    double x = 0, y = 0;
    bool operator==(const Chromaticity&) const = default;
};
/// x = X / (X + Y + Z), y = Y / (X + Y + Z); (0, 0) for black.
Chromaticity XYZToChromaticity(const Vec3d& xyz);
/// XYZ of chromaticity xy with luminance Y.
Vec3d ChromaticityToXYZ(const Chromaticity& xy, double Y = 1.0);

/// XYZ of a spectral power distribution: (Σ x̄ s, Σ ȳ s, Σ z̄ s) / Σ ȳ over 1 nm steps, so a constant
/// spectrum of 1 has Y = 1 (the convention of pbrt-v4's SpectrumToXYZ).
Vec3d SpectrumToXYZ(const Spectrum& s);
/// XYZ of a reflectance (or transmittance) seen under `illuminant`, normalised so that a perfect
/// reflector has Y = 1 (CIE 15:2004 eq. 7.1-7.3 with k = 1 / Σ S ȳ).
Vec3d ReflectanceToXYZ(const Spectrum& reflectance, const Spectrum& illuminant);
/// The film's estimator of the XYZ of radiance L carried at wavelengths `lambda`: the average over
/// the kNumWavelengths samples of cmf(λ_i) L_i / pdf_i, divided by ∫ȳ (pbrt-v4 RGBFilm convention),
/// so an illuminant's Y is its luminance relative to ∫ȳ. Terminated wavelengths (pdf 0) count 0.
Vec3d SampledToXYZ(const SampledSpectrum& L, const SampledWavelengths& lambda);

/// An RGB colour space built from its primaries' and white point's chromaticities (SMPTE RP
/// 177-1993 derivation of the normalised primary matrix).
class RgbColorSpace {
  public:
    RgbColorSpace(std::string name, Chromaticity r, Chromaticity g, Chromaticity b,
                  Chromaticity white);

    /// IEC 61966-2-1 sRGB / ITU-R BT.709 primaries, D65 white.
    static const RgbColorSpace& Srgb();
    /// ITU-R BT.2020 primaries, D65 white.
    static const RgbColorSpace& Rec2020();
    /// ACEScg (AP1 primaries, ACES white ≈ D60; SMPTE ST 2065-1 / Academy S-2014-004).
    static const RgbColorSpace& AcesCg();
    /// By name: "srgb", "rec2020", "acescg" (case-insensitive); NotFound lists the names.
    static StatusOr<const RgbColorSpace*> Named(std::string_view name);

    const std::string& name() const { return name_; }
    Chromaticity r() const { return r_; }
    Chromaticity g() const { return g_; }
    Chromaticity b() const { return b_; }
    Chromaticity white() const { return white_; }
    /// XYZ (white Y = 1) -> linear RGB in this space.
    const Mat3d& xyz_to_rgb() const { return xyz_to_rgb_; }
    const Mat3d& rgb_to_xyz() const { return rgb_to_xyz_; }
    Vec3d ToRgb(const Vec3d& xyz) const { return xyz_to_rgb_ * xyz; }
    Vec3d ToXyz(const Vec3d& rgb) const { return rgb_to_xyz_ * rgb; }

  private:
    std::string name_;
    Chromaticity r_, g_, b_, white_;
    Mat3d rgb_to_xyz_, xyz_to_rgb_;
};

/// Chromatic adaptation transforms (von Kries-type: scale cone-like responses, Lam 1985 / CIE 160).
enum class AdaptationMethod {
    kBradford,    ///< Lam (1985), the ICC's and Lindbloom's Bradford matrix.
    kVonKries,    ///< Hunt-Pointer-Estévez cone fundamentals (normalised to D65).
    kXyzScaling,  ///< plain XYZ scaling (for comparison only).
    kCat02,       ///< CIECAM02's CAT02 (CIE 159:2004), with full adaptation.
    kCat16,       ///< CAM16's CAT16 (Li et al. 2017), with full adaptation.
};
/// The method named "bradford", "von_kries", "xyz_scaling", "cat02" or "cat16"; nothing otherwise.
std::optional<AdaptationMethod> ParseAdaptationMethod(std::string_view name);

/// The 3x3 matrix that maps XYZ seen under white `src` to corresponding XYZ under white `dst`.
Mat3d ChromaticAdaptationMatrix(const Chromaticity& src, const Chromaticity& dst,
                                AdaptationMethod method = AdaptationMethod::kBradford);
/// White balance: XYZ -> linear RGB of `space`, adapting the illuminant's white (`scene_white`) to
/// the space's white so that a neutral surface under that illuminant comes out neutral.
Mat3d WhiteBalancedXyzToRgb(const RgbColorSpace& space, const Chromaticity& scene_white,
                            AdaptationMethod method = AdaptationMethod::kBradford);

/// The sRGB transfer curve (IEC 61966-2-1): linear [0, 1] -> encoded [0, 1], and back.
double SrgbEncode(double linear);
double SrgbDecode(double encoded);
/// Exposure: multiplies linear values by 2^ev.
Vec3d ApplyExposure(const Vec3d& rgb, double ev);
/// Linear sRGB -> 8-bit sRGB: clamp to [0, 1], encode, round to nearest.
std::array<uint8_t, 3> LinearSrgbTo8Bit(const Vec3d& linear_rgb);

/// CIE 1976 L*a*b* of `xyz` relative to the reference white `white_xyz` (CIE 15:2004 §8.2.1).
Vec3d XYZToLab(const Vec3d& xyz, const Vec3d& white_xyz);
/// CIE 1976 ΔE*ab.
double DeltaE76(const Vec3d& lab1, const Vec3d& lab2);

/// Correlated colour temperature by McCamy's cubic (McCamy 1992, Color Res. Appl. 17(2) 142-144,
/// erratum 18(2) 150); accurate to ~2 K over 2856-6504 K near the Planckian locus.
double CctMcCamy(const Chromaticity& xy);
/// Correlated colour temperature by Robertson's method (Robertson 1968, JOSA 58(11) 1528-1535):
/// linear interpolation between the 31 isotemperature lines of Wyszecki & Stiles (1982) Table
/// 1(3.11) in the CIE 1960 (u, v) diagram; 1667 K to infinity. NaN outside the table's reach (far
/// from the locus).
double CctRobertson(const Chromaticity& xy);

}  // namespace nave
