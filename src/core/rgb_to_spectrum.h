#pragma once
// RGB -> spectrum uplift by the sigmoid-polynomial method of Jakob & Hanika 2019 ("A
// Low-Dimensional Function Space for Efficient Spectral Upsampling", Computer Graphics Forum
// 38(2), EGSR 2019): a reflectance is s(λ) = S(c0 t² + c1 t + c2), S(x) = 1/2 + x / (2 sqrt(1 +
// x²)) (paper eqs. 3-4), so it is smooth and always in (0, 1). The coefficients for an RGB
// colour come from a 3-D table per colour space, solved by nave itself with Gauss-Newton against
// the CIE 1931 2° observer under the space's white illuminant (paper §3-4), and interpolated
// trilinearly at lookup time.

#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "src/core/color.h"
#include "src/core/spectrum.h"
#include "src/core/vecmath.h"

namespace nave {

/// A sigmoid-polynomial spectrum s(λ) = S(c0 t² + c1 t + c2) with the normalised wavelength t =
/// (λ - kLambdaMinNm) / (kLambdaMaxNm - kLambdaMinNm). The paper writes the polynomial in λ; nave
/// keeps it in t because the coefficients then stay of order 1 in float (the two forms describe the
/// same function space). c2 = ±infinity gives the flat spectra 1 and 0. A value type.
struct SigmoidPolynomial {
    float c0 = 0.f, c1 = 0.f, c2 = 0.f;

    /// S(x) = 1/2 + x / (2 sqrt(1 + x²)) (Jakob & Hanika 2019, eq. 4), with S(±inf) = 1, 0.
    static float Sigmoid(float x) {
        if (std::isinf(x)) return x > 0.f ? 1.f : 0.f;
        return 0.5f + x / (2.f * std::sqrt(1.f + x * x));
    }
    /// The normalised wavelength t of `lambda_nm`.
    static float NormalizedWavelength(float lambda_nm) {
        return (lambda_nm - kLambdaMinNm) / (kLambdaMaxNm - kLambdaMinNm);
    }
    /// s(λ), in [0, 1].
    float Evaluate(float lambda_nm) const {
        float t = NormalizedWavelength(lambda_nm);
        return Sigmoid((c0 * t + c1) * t + c2);
    }
    SampledSpectrum Sample(const SampledWavelengths& lambda) const {
        SampledSpectrum s;
        for (int i = 0; i < kNumWavelengths; ++i) s[i] = Evaluate(lambda.lambda_nm(i));
        return s;
    }
    /// The maximum over [kLambdaMinNm, kLambdaMaxNm] (at an end or at the parabola's vertex).
    float MaxValue() const;
    /// The 1 nm tabulation, for colorimetry and tests.
    Spectrum ToSpectrum() const;
};

/// The coefficient table of one RGB colour space. For an RGB colour in [0, 1]³ whose largest
/// component is index l, the table is indexed by z = rgb[l] (on a grid that is denser near 0 and
/// 1, where the coefficients change fastest) and by x = rgb[(l+1)%3] / z, y = rgb[(l+2)%3] / z in
/// [0, 1] (Jakob & Hanika 2019 §4: three tables, one per maximal component).
///
/// Tables are computed lazily at first use of a colour space and cached in memory for the life of
/// the process (For()); the solve runs on one thread per maximal component and takes about half a
/// second for sRGB on nave's CI machine (see docs/textures.md). Thread-safe after construction.
class RgbToSpectrumTable {
  public:
    /// Grid points per axis (z, y, x).
    static constexpr int kResolution = 32;

    /// Solves the table for `space` by Gauss-Newton (residual in CIELAB under the space's white,
    /// as in the paper); the space's white illuminant is D65 when its white point is D65's and the
    /// CIE daylight of the white point's CCT otherwise.
    explicit RgbToSpectrumTable(const RgbColorSpace& space);

    /// The table of `space`, computed at the first call for that space (by name) and shared.
    /// Thread-safe.
    static const RgbToSpectrumTable& For(const RgbColorSpace& space);

    /// The coefficients of linear `rgb`; components are clamped to [0, 1] first. Greys (r = g = b)
    /// are exact: the constant S⁻¹(v), so (1, 1, 1) is a flat 1 and (0, 0, 0) a flat 0.
    SigmoidPolynomial Lookup(const Vec3f& rgb) const;

    /// The illuminant of the space's white, scaled so that its Y (SpectrumToXYZ) is 1.
    const Spectrum& illuminant() const { return illuminant_; }
    const RgbColorSpace& space() const { return *space_; }
    /// Largest CIELAB ΔE*ab between a table node's target and its fitted spectrum (a quality
    /// measure of the solve, reported in docs and checked by tests).
    double max_node_delta_e() const { return max_node_delta_e_; }

  private:
    const RgbColorSpace* space_;
    Spectrum illuminant_;
    std::array<float, kResolution> z_nodes_{};
    // coefficients_[((l * R + zi) * R + yi) * R + xi] for l in 0..2.
    std::vector<std::array<float, 3>> coefficients_;
    double max_node_delta_e_ = 0.0;
};

/// A reflectance (albedo) lifted from linear RGB of `space`: at most 1 at every wavelength. The
/// RGB is clamped to [0, 1].
SigmoidPolynomial UpliftReflectance(const Vec3f& rgb,
                                    const RgbColorSpace& space = RgbColorSpace::Srgb());

/// An emission spectrum lifted from linear RGB (unbounded, ≥ 0): scale · s(λ) · W(λ), where W is
/// the space's white illuminant normalised to Y = 1, scale = 2 max(rgb) and s the reflectance of
/// rgb / scale (so s stays in the table's well-conditioned interior). Its XYZ under the CIE
/// observer (SpectrumToXYZ) is the XYZ of `rgb` in `space`.
class RgbEmission {
  public:
    RgbEmission() = default;
    RgbEmission(const Vec3f& rgb, const RgbColorSpace& space = RgbColorSpace::Srgb());
    float Evaluate(float lambda_nm) const {
        if (scale_ == 0.f) return 0.f;
        return scale_ * shape_.Evaluate(lambda_nm) * illuminant_->Evaluate(lambda_nm);
    }
    SampledSpectrum Sample(const SampledWavelengths& lambda) const {
        SampledSpectrum s;
        for (int i = 0; i < kNumWavelengths; ++i) s[i] = Evaluate(lambda.lambda_nm(i));
        return s;
    }
    Spectrum ToSpectrum() const;

  private:
    float scale_ = 0.f;
    SigmoidPolynomial shape_;
    const Spectrum* illuminant_ = nullptr;
};

}  // namespace nave
