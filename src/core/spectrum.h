#pragma once
// Spectra for nave's spectral rendering: a few wavelengths carried by each path (SampledSpectrum,
// SampledWavelengths) and densely tabulated spectra (Spectrum) for illuminants, reflectances,
// optical constants. All wavelengths are in nanometres (vacuum).

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "src/core/status.h"

namespace nave {

/// Number of wavelengths carried by one path (hero wavelength + 3 stratified rotations).
inline constexpr int kNumWavelengths = 4;
/// The spectral range nave renders and tabulates (the range of the CIE 1931 1 nm tables).
inline constexpr float kLambdaMinNm = 360.f;
inline constexpr float kLambdaMaxNm = 830.f;

/// The values of a spectrum at the kNumWavelengths wavelengths of one path. A cheap value type.
class SampledSpectrum {
  public:
    /// All zero.
    constexpr SampledSpectrum() = default;
    /// All equal to `c`.
    constexpr explicit SampledSpectrum(float c) { values_.fill(c); }
    constexpr explicit SampledSpectrum(const std::array<float, kNumWavelengths>& v) : values_(v) {}

    constexpr float operator[](int i) const { return values_[i]; }
    constexpr float& operator[](int i) { return values_[i]; }

    SampledSpectrum& operator+=(const SampledSpectrum& s) {
        for (int i = 0; i < kNumWavelengths; ++i) values_[i] += s.values_[i];
        return *this;
    }
    SampledSpectrum& operator-=(const SampledSpectrum& s) {
        for (int i = 0; i < kNumWavelengths; ++i) values_[i] -= s.values_[i];
        return *this;
    }
    SampledSpectrum& operator*=(const SampledSpectrum& s) {
        for (int i = 0; i < kNumWavelengths; ++i) values_[i] *= s.values_[i];
        return *this;
    }
    /// Component-wise division; the caller guarantees non-zero divisors (see SafeDiv otherwise).
    SampledSpectrum& operator/=(const SampledSpectrum& s) {
        for (int i = 0; i < kNumWavelengths; ++i) values_[i] /= s.values_[i];
        return *this;
    }
    SampledSpectrum& operator*=(float a) {
        for (float& v : values_) v *= a;
        return *this;
    }
    SampledSpectrum& operator/=(float a) {
        for (float& v : values_) v /= a;
        return *this;
    }
    SampledSpectrum& operator+=(float a) {
        for (float& v : values_) v += a;
        return *this;
    }
    SampledSpectrum operator+(const SampledSpectrum& s) const {
        return SampledSpectrum(*this) += s;
    }
    SampledSpectrum operator-(const SampledSpectrum& s) const {
        return SampledSpectrum(*this) -= s;
    }
    SampledSpectrum operator*(const SampledSpectrum& s) const {
        return SampledSpectrum(*this) *= s;
    }
    SampledSpectrum operator/(const SampledSpectrum& s) const {
        return SampledSpectrum(*this) /= s;
    }
    SampledSpectrum operator*(float a) const { return SampledSpectrum(*this) *= a; }
    SampledSpectrum operator/(float a) const { return SampledSpectrum(*this) /= a; }
    SampledSpectrum operator+(float a) const { return SampledSpectrum(*this) += a; }
    SampledSpectrum operator-(float a) const { return SampledSpectrum(*this) += -a; }
    SampledSpectrum operator-() const {
        SampledSpectrum r;
        for (int i = 0; i < kNumWavelengths; ++i) r.values_[i] = -values_[i];
        return r;
    }
    bool operator==(const SampledSpectrum& s) const = default;

    /// True when any value is non-zero.
    explicit operator bool() const { return !IsZero(); }
    bool IsZero() const {
        for (float v : values_)
            if (v != 0.f) return false;
        return true;
    }
    bool HasNaN() const {
        for (float v : values_)
            if (std::isnan(v)) return true;
        return false;
    }
    float Average() const {
        float s = 0.f;
        for (float v : values_) s += v;
        return s / kNumWavelengths;
    }
    float MaxValue() const {
        float m = values_[0];
        for (float v : values_) m = std::max(m, v);
        return m;
    }
    float MinValue() const {
        float m = values_[0];
        for (float v : values_) m = std::min(m, v);
        return m;
    }
    const std::array<float, kNumWavelengths>& values() const { return values_; }

  private:
    std::array<float, kNumWavelengths> values_{};
};

inline SampledSpectrum operator*(float a, const SampledSpectrum& s) { return s * a; }
/// a / b component-wise, 0 where b is 0 (pdfs of terminated wavelengths).
SampledSpectrum SafeDiv(const SampledSpectrum& a, const SampledSpectrum& b);
SampledSpectrum Exp(const SampledSpectrum& s);
SampledSpectrum Sqrt(const SampledSpectrum& s);
SampledSpectrum Clamp(const SampledSpectrum& s, float lo, float hi);
/// max(s, 0) component-wise.
SampledSpectrum ClampZero(const SampledSpectrum& s);
/// (1 - t) a + t b.
SampledSpectrum Lerp(float t, const SampledSpectrum& a, const SampledSpectrum& b);
std::ostream& operator<<(std::ostream& os, const SampledSpectrum& s);

/// pdf (per nm) of the visible-wavelength importance sampling of SampledWavelengths::SampleVisible:
/// p(λ) ∝ sech²(0.0072 (λ - 538)) on [360, 830] nm (the distribution of pbrt-v4, Pharr, Jakob &
/// Humphreys 2023, §4.6.5, which follows the shape of the CIE ȳ curve with wide tails; normalised
/// here analytically). Zero outside [360, 830].
float VisibleWavelengthsPdf(float lambda_nm);
/// Inverts the CDF of VisibleWavelengthsPdf: u in [0, 1) -> λ in [360, 830] nm.
float SampleVisibleWavelengths(float u);
/// The CDF of VisibleWavelengthsPdf: λ in [360, 830] nm -> u in [0, 1], SampleVisibleWavelengths'
/// inverse (to a few float ulps).
float VisibleWavelengthsCdf(float lambda_nm);

/// The kNumWavelengths wavelengths one path carries and the pdf each was drawn with.
/// Hero-wavelength sampling (Wilkie et al. 2014): the first is drawn from `u`, the others are
/// rotations of u by i/kNumWavelengths, so the four are stratified over the range.
class SampledWavelengths {
  public:
    /// Uniform over [lo_nm, hi_nm] (pdf 1/(hi - lo) each).
    static SampledWavelengths SampleUniform(float u, float lo_nm = kLambdaMinNm,
                                            float hi_nm = kLambdaMaxNm);
    /// Importance-sampled over the visible range with VisibleWavelengthsPdf.
    static SampledWavelengths SampleVisible(float u);

    float lambda_nm(int i) const { return lambda_nm_[i]; }
    float operator[](int i) const { return lambda_nm_[i]; }
    /// The pdf (per nm) of each wavelength; 0 for terminated secondary wavelengths.
    SampledSpectrum Pdf() const { return SampledSpectrum(pdf_); }

    /// Keeps only the hero wavelength (index 0), for dispersive refraction where the paths of the
    /// wavelengths part. The hero's pdf is divided by kNumWavelengths so that the film's estimator
    /// (an average over the kNumWavelengths samples of f/pdf) stays unbiased.
    void TerminateSecondary();
    bool SecondaryTerminated() const;

    bool operator==(const SampledWavelengths& o) const = default;

  private:
    std::array<float, kNumWavelengths> lambda_nm_{};
    std::array<float, kNumWavelengths> pdf_{};
};

/// A spectrum tabulated at every nanometre from kLambdaMinNm to kLambdaMaxNm (471 values),
/// evaluated by linear interpolation; 0 outside the range. A value type (about 2 KB); build once
/// per scene object and sample per path with Sample().
class Spectrum {
  public:
    static constexpr int kNumSamples = int(kLambdaMaxNm - kLambdaMinNm) + 1;

    /// All zero.
    Spectrum();
    static Spectrum Constant(float value);
    /// Linear interpolation between (lambdas_nm[i], values[i]); lambdas_nm strictly increasing and
    /// of the same size as values (else an InvalidArgument error). Outside the data the end values
    /// are held, so a reflectance measured 380-730 nm stays sensible at 360 and 830 nm.
    static StatusOr<Spectrum> FromPiecewiseLinear(const std::vector<double>& lambdas_nm,
                                                  const std::vector<double>& values);
    /// Like FromPiecewiseLinear for tables that are known to be valid (compiled-in data): CHECKs.
    static Spectrum FromPiecewiseLinearOrDie(const std::vector<double>& lambdas_nm,
                                             const std::vector<double>& values);
    /// Samples f at every nanometre.
    template <typename F>
    static Spectrum FromFunction(F&& f) {
        Spectrum s;
        for (int i = 0; i < kNumSamples; ++i) s.values_[i] = float(f(double(kLambdaMinNm) + i));
        return s;
    }
    /// Planck's law for a black body at `t_kelvin`, normalised to a peak of 1 over all wavelengths
    /// (scale it to the wanted power); see PlanckRadiance for absolute values.
    static Spectrum Blackbody(double t_kelvin);
    /// The CIE daylight illuminant of correlated colour temperature `cct_kelvin` (4000-25000 K),
    /// from the S0, S1, S2 components (CIE 15:2004 §3.1), normalised to 100 at 560 nm.
    static Spectrum CieIlluminantD(double cct_kelvin);

    /// Linear interpolation between the 1 nm samples; 0 outside [kLambdaMinNm, kLambdaMaxNm].
    float Evaluate(float lambda_nm) const {
        float x = lambda_nm - kLambdaMinNm;
        if (!(x >= 0.f) || x > float(kNumSamples - 1)) return 0.f;
        int i = std::min(int(x), kNumSamples - 2);
        float t = x - float(i);
        return values_[i] + t * (values_[i + 1] - values_[i]);
    }
    float operator()(float lambda_nm) const { return Evaluate(lambda_nm); }
    /// The values at a path's wavelengths.
    SampledSpectrum Sample(const SampledWavelengths& lambda) const {
        SampledSpectrum s;
        for (int i = 0; i < kNumWavelengths; ++i) s[i] = Evaluate(lambda.lambda_nm(i));
        return s;
    }
    /// The value of the 1 nm sample at kLambdaMinNm + i.
    float sample(int i) const { return values_[i]; }
    float MaxValue() const;
    /// True if all samples are equal (no dispersion for an index of refraction).
    bool IsConstant() const;

    Spectrum& operator*=(float a);
    Spectrum& operator*=(const Spectrum& s);
    Spectrum& operator+=(const Spectrum& s);
    Spectrum operator*(float a) const { return Spectrum(*this) *= a; }
    Spectrum operator*(const Spectrum& s) const { return Spectrum(*this) *= s; }
    Spectrum operator+(const Spectrum& s) const { return Spectrum(*this) += s; }

  private:
    std::array<float, kNumSamples> values_{};
};

/// Planck's law: spectral radiance of a black body in W·sr⁻¹·m⁻²·nm⁻¹ (CODATA 2018 constants).
double PlanckRadiance(double lambda_nm, double t_kelvin);
/// Planck's law relative to its peak over all wavelengths (Wien's λmax = b / T): 1 at the peak.
double PlanckRelativeToPeak(double lambda_nm, double t_kelvin);

/// A table of spectra read from CSV text: one wavelength column (nm) then one or more value
/// columns.
struct SpectraTable {
    /// Names of the value columns (from the header row, else "1", "2", ...).
    std::vector<std::string> names;
    std::vector<double> lambda_nm;
    /// columns[c][row].
    std::vector<std::vector<double>> columns;

    /// The column with this name, or NotFound naming the columns there are.
    StatusOr<Spectrum> ToSpectrum(std::string_view name) const;
    /// Column `index` (0 = first value column) as a Spectrum.
    Spectrum ToSpectrum(int index) const;
};

/// Parses CSV spectra: '#' starts a comment, blank lines are skipped, an optional header row (first
/// non-comment line with a non-numeric wavelength field), then rows "lambda_nm,v1[,v2...]" with
/// strictly increasing wavelengths and the same number of columns. Separators: ',', ';' or tabs.
/// Errors name `source_name` and the line: "gold.csv:12: expected 3 columns, found 2".
StatusOr<SpectraTable> ParseSpectraCsv(std::string_view text, std::string_view source_name);
/// Reads and parses a CSV file of spectra (see ParseSpectraCsv).
StatusOr<SpectraTable> LoadSpectraCsv(const std::filesystem::path& path);

}  // namespace nave
