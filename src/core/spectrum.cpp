#include "src/core/spectrum.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>

#include "src/core/file.h"
#include "src/core/spectrum_data.h"

namespace nave {

SampledSpectrum SafeDiv(const SampledSpectrum& a, const SampledSpectrum& b) {
    SampledSpectrum r;
    for (int i = 0; i < kNumWavelengths; ++i) r[i] = b[i] != 0.f ? a[i] / b[i] : 0.f;
    return r;
}

SampledSpectrum Exp(const SampledSpectrum& s) {
    SampledSpectrum r;
    for (int i = 0; i < kNumWavelengths; ++i) r[i] = std::exp(s[i]);
    return r;
}

SampledSpectrum Sqrt(const SampledSpectrum& s) {
    SampledSpectrum r;
    for (int i = 0; i < kNumWavelengths; ++i) r[i] = std::sqrt(s[i]);
    return r;
}

SampledSpectrum Clamp(const SampledSpectrum& s, float lo, float hi) {
    SampledSpectrum r;
    for (int i = 0; i < kNumWavelengths; ++i) r[i] = std::clamp(s[i], lo, hi);
    return r;
}

SampledSpectrum ClampZero(const SampledSpectrum& s) {
    SampledSpectrum r;
    for (int i = 0; i < kNumWavelengths; ++i) r[i] = std::max(s[i], 0.f);
    return r;
}

SampledSpectrum Lerp(float t, const SampledSpectrum& a, const SampledSpectrum& b) {
    return a * (1.f - t) + b * t;
}

std::ostream& operator<<(std::ostream& os, const SampledSpectrum& s) {
    os << "[";
    for (int i = 0; i < kNumWavelengths; ++i) os << (i ? ", " : "") << s[i];
    return os << "]";
}

// ---- Wavelength sampling

namespace {

// p(λ) = A sech²(a (λ - b)): the shape used by pbrt-v4 (§4.6.5) for visible wavelengths. Its CDF is
// proportional to tanh(a (λ - b)), so normalisation and inversion are closed-form; we derive them
// here rather than hard-coding the book's rounded constants.
constexpr double kVisA = 0.0072;
constexpr double kVisB = 538.0;

struct VisibleSampling {
    double t0, t1, norm;
    VisibleSampling() {
        t0 = std::tanh(kVisA * (double(kLambdaMinNm) - kVisB));
        t1 = std::tanh(kVisA * (double(kLambdaMaxNm) - kVisB));
        // ∫ sech²(a(λ-b)) dλ over [min, max] = (t1 - t0) / a.
        norm = kVisA / (t1 - t0);
    }
};

const VisibleSampling& Vis() {
    static const VisibleSampling v;
    return v;
}

}  // namespace

float VisibleWavelengthsPdf(float lambda_nm) {
    if (lambda_nm < kLambdaMinNm || lambda_nm > kLambdaMaxNm) return 0.f;
    double c = std::cosh(kVisA * (double(lambda_nm) - kVisB));
    return float(Vis().norm / (c * c));
}

float SampleVisibleWavelengths(float u) {
    const VisibleSampling& v = Vis();
    double t = v.t0 + double(u) * (v.t1 - v.t0);
    double lambda = kVisB + std::atanh(t) / kVisA;
    return float(std::clamp(lambda, double(kLambdaMinNm), double(kLambdaMaxNm)));
}

float VisibleWavelengthsCdf(float lambda_nm) {
    const VisibleSampling& v = Vis();
    // ∫ p from 360 nm to λ = (tanh(a (λ - b)) - t0) / (t1 - t0).
    const double t = std::tanh(kVisA * (double(lambda_nm) - kVisB));
    return float(std::clamp((t - v.t0) / (v.t1 - v.t0), 0.0, 1.0));
}

SampledWavelengths SampledWavelengths::SampleUniform(float u, float lo_nm, float hi_nm) {
    NAVE_CHECK_LT(lo_nm, hi_nm);
    SampledWavelengths w;
    // Hero wavelength (Wilkie et al. 2014, "Hero wavelength spectral sampling"): the others are
    // equally spaced rotations of the first over the range.
    w.lambda_nm_[0] = lo_nm + u * (hi_nm - lo_nm);
    float delta = (hi_nm - lo_nm) / kNumWavelengths;
    for (int i = 1; i < kNumWavelengths; ++i) {
        float l = w.lambda_nm_[i - 1] + delta;
        if (l > hi_nm) l = lo_nm + (l - hi_nm);
        w.lambda_nm_[i] = l;
    }
    w.pdf_.fill(1.f / (hi_nm - lo_nm));
    return w;
}

SampledWavelengths SampledWavelengths::SampleVisible(float u) {
    SampledWavelengths w;
    for (int i = 0; i < kNumWavelengths; ++i) {
        // Rotations of u in sample space keep the four wavelengths stratified under the pdf.
        float up = u + float(i) / kNumWavelengths;
        if (up >= 1.f) up -= 1.f;
        w.lambda_nm_[i] = SampleVisibleWavelengths(up);
        w.pdf_[i] = VisibleWavelengthsPdf(w.lambda_nm_[i]);
    }
    return w;
}

void SampledWavelengths::TerminateSecondary() {
    if (SecondaryTerminated()) return;
    for (int i = 1; i < kNumWavelengths; ++i) pdf_[i] = 0.f;
    pdf_[0] /= kNumWavelengths;
}

bool SampledWavelengths::SecondaryTerminated() const {
    for (int i = 1; i < kNumWavelengths; ++i)
        if (pdf_[i] != 0.f) return false;
    return true;
}

// ---- Spectrum

Spectrum::Spectrum() = default;

Spectrum Spectrum::Constant(float value) {
    Spectrum s;
    s.values_.fill(value);
    return s;
}

StatusOr<Spectrum> Spectrum::FromPiecewiseLinear(const std::vector<double>& lambdas_nm,
                                                 const std::vector<double>& values) {
    if (lambdas_nm.size() != values.size())
        return InvalidArgumentError("piecewise-linear spectrum: {} wavelengths but {} values",
                                    lambdas_nm.size(), values.size());
    if (lambdas_nm.empty()) return InvalidArgumentError("piecewise-linear spectrum: no samples");
    for (size_t i = 0; i < lambdas_nm.size(); ++i) {
        if (!std::isfinite(lambdas_nm[i]) || !std::isfinite(values[i]))
            return InvalidArgumentError("piecewise-linear spectrum: sample {} is not finite", i);
        if (i > 0 && !(lambdas_nm[i] > lambdas_nm[i - 1]))
            return InvalidArgumentError(
                "piecewise-linear spectrum: wavelengths must increase, found {} nm after {} nm",
                lambdas_nm[i], lambdas_nm[i - 1]);
    }
    return FromFunction([&](double l) {
        if (l <= lambdas_nm.front()) return values.front();
        if (l >= lambdas_nm.back()) return values.back();
        size_t hi =
            size_t(std::upper_bound(lambdas_nm.begin(), lambdas_nm.end(), l) - lambdas_nm.begin());
        size_t lo = hi - 1;
        double t = (l - lambdas_nm[lo]) / (lambdas_nm[hi] - lambdas_nm[lo]);
        return values[lo] + t * (values[hi] - values[lo]);
    });
}

Spectrum Spectrum::FromPiecewiseLinearOrDie(const std::vector<double>& lambdas_nm,
                                            const std::vector<double>& values) {
    StatusOr<Spectrum> s = FromPiecewiseLinear(lambdas_nm, values);
    NAVE_CHECK(s.ok()) << s.status().ToString();
    return std::move(s).value();
}

double PlanckRadiance(double lambda_nm, double t_kelvin) {
    if (t_kelvin <= 0) return 0;
    // Planck's law, B(λ, T) = 2hc² / λ⁵ / (exp(hc / (λ k T)) - 1), CODATA 2018 exact constants.
    constexpr double kH = 6.62607015e-34;  // J s
    constexpr double kC = 299792458.0;     // m/s
    constexpr double kKb = 1.380649e-23;   // J/K
    double l = lambda_nm * 1e-9;
    double le =
        (2 * kH * kC * kC) / (l * l * l * l * l * (std::expm1((kH * kC) / (l * kKb * t_kelvin))));
    return le * 1e-9;  // per metre of wavelength -> per nanometre
}

double PlanckRelativeToPeak(double lambda_nm, double t_kelvin) {
    if (t_kelvin <= 0) return 0;
    // Wien's displacement law gives the peak: λmax = b / T, b = 2.897771955e-3 m K (CODATA 2018).
    const double peak_nm = 2.897771955e6 / t_kelvin;
    return PlanckRadiance(lambda_nm, t_kelvin) / PlanckRadiance(peak_nm, t_kelvin);
}

Spectrum Spectrum::Blackbody(double t_kelvin) {
    NAVE_CHECK_GT(t_kelvin, 0.0);
    return FromFunction([&](double l) { return PlanckRelativeToPeak(l, t_kelvin); });
}

Spectrum Spectrum::CieIlluminantD(double cct_kelvin) {
    // CIE 15:2004 §3.1 eqs. (3.3)-(3.6): chromaticity of daylight from the CCT, then the weights of
    // the characteristic vectors S1, S2. Valid for 4000 K to 25000 K; clamp to that range.
    double t = std::clamp(cct_kelvin, 4000.0, 25000.0);
    double xd = t <= 7000.0
                    ? -4.6070e9 / (t * t * t) + 2.9678e6 / (t * t) + 0.09911e3 / t + 0.244063
                    : -2.0064e9 / (t * t * t) + 1.9018e6 / (t * t) + 0.24748e3 / t + 0.237040;
    double yd = -3.000 * xd * xd + 2.870 * xd - 0.275;
    double m = 0.0241 + 0.2562 * xd - 0.7341 * yd;
    double m1 = (-1.3515 - 1.7703 * xd + 5.9114 * yd) / m;
    double m2 = (0.0300 - 31.4424 * xd + 30.0717 * yd) / m;
    // CIE 15:2004 note 3 to §3.1: M1 and M2 are rounded to three decimals before use.
    m1 = std::round(m1 * 1000.0) / 1000.0;
    m2 = std::round(m2 * 1000.0) / 1000.0;
    const SpectraTable& comp = EmbeddedSpectraTable("cie_daylight_components.csv");
    std::vector<double> values(comp.lambda_nm.size());
    for (size_t i = 0; i < values.size(); ++i)
        values[i] = comp.columns[0][i] + m1 * comp.columns[1][i] + m2 * comp.columns[2][i];
    // The 5 nm components are interpolated linearly to 1 nm, as the CIE does for its 1 nm tables.
    return FromPiecewiseLinearOrDie(comp.lambda_nm, values);
}

float Spectrum::MaxValue() const { return *std::max_element(values_.begin(), values_.end()); }

bool Spectrum::IsConstant() const {
    for (float v : values_)
        if (v != values_[0]) return false;
    return true;
}

Spectrum& Spectrum::operator*=(float a) {
    for (float& v : values_) v *= a;
    return *this;
}
Spectrum& Spectrum::operator*=(const Spectrum& s) {
    for (int i = 0; i < kNumSamples; ++i) values_[i] *= s.values_[i];
    return *this;
}
Spectrum& Spectrum::operator+=(const Spectrum& s) {
    for (int i = 0; i < kNumSamples; ++i) values_[i] += s.values_[i];
    return *this;
}

// ---- CSV

namespace {

std::string_view Trim(std::string_view s) {
    while (!s.empty() &&
           (s.front() == ' ' || s.front() == '\t' || s.front() == '\r' || s.front() == '"'))
        s.remove_prefix(1);
    while (!s.empty() &&
           (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '"'))
        s.remove_suffix(1);
    return s;
}

std::vector<std::string_view> SplitFields(std::string_view line) {
    std::vector<std::string_view> fields;
    size_t start = 0;
    for (size_t i = 0; i <= line.size(); ++i) {
        if (i == line.size() || line[i] == ',' || line[i] == ';' || line[i] == '\t') {
            fields.push_back(Trim(line.substr(start, i - start)));
            start = i + 1;
        }
    }
    return fields;
}

bool ParseDouble(std::string_view s, double* out) {
    if (s.empty()) return false;
    if (s.front() == '+') s.remove_prefix(1);
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
    return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(*out);
}

}  // namespace

StatusOr<SpectraTable> ParseSpectraCsv(std::string_view text, std::string_view source_name) {
    SpectraTable table;
    // Spreadsheet exports often start with a UTF-8 byte-order mark.
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    size_t num_columns = 0;  // value columns, fixed by the header or the first data row
    int line_number = 0;
    bool seen_data = false;
    size_t pos = 0;
    while (pos <= text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_number;
        if (size_t hash = line.find('#'); hash != std::string_view::npos)
            line = line.substr(0, hash);
        line = Trim(line);
        if (line.empty()) continue;
        std::vector<std::string_view> fields = SplitFields(line);
        double lambda = 0;
        if (!ParseDouble(fields[0], &lambda)) {
            if (seen_data || !table.names.empty())
                return InvalidArgumentError("{}:{}: expected a wavelength in nm, found '{}'",
                                            source_name, line_number, fields[0]);
            // Header row.
            if (fields.size() < 2)
                return InvalidArgumentError(
                    "{}:{}: header needs a wavelength column and at least one value column",
                    source_name, line_number);
            for (size_t i = 1; i < fields.size(); ++i) table.names.emplace_back(fields[i]);
            num_columns = fields.size() - 1;
            continue;
        }
        if (num_columns == 0) {
            if (fields.size() < 2)
                return InvalidArgumentError(
                    "{}:{}: expected a wavelength and at least one value, found 1 column",
                    source_name, line_number);
            num_columns = fields.size() - 1;
        }
        if (fields.size() != num_columns + 1)
            return InvalidArgumentError("{}:{}: expected {} columns, found {}", source_name,
                                        line_number, num_columns + 1, fields.size());
        if (!table.lambda_nm.empty() && !(lambda > table.lambda_nm.back()))
            return InvalidArgumentError("{}:{}: wavelengths must increase, found {} nm after {} nm",
                                        source_name, line_number, lambda, table.lambda_nm.back());
        if (lambda <= 0)
            return InvalidArgumentError("{}:{}: wavelength must be positive, found {}", source_name,
                                        line_number, lambda);
        if (table.columns.empty()) table.columns.resize(num_columns);
        table.lambda_nm.push_back(lambda);
        for (size_t c = 0; c < num_columns; ++c) {
            double v = 0;
            if (!ParseDouble(fields[c + 1], &v))
                return InvalidArgumentError("{}:{}: column {}: expected a number, found '{}'",
                                            source_name, line_number, c + 2, fields[c + 1]);
            table.columns[c].push_back(v);
        }
        seen_data = true;
    }
    if (table.lambda_nm.empty())
        return InvalidArgumentError("{}: no spectral data rows (wavelength_nm,value,...)",
                                    source_name);
    if (table.names.empty())
        for (size_t c = 0; c < num_columns; ++c) table.names.push_back(std::to_string(c + 1));
    return table;
}

StatusOr<SpectraTable> LoadSpectraCsv(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
    return ParseSpectraCsv(text, path.string());
}

StatusOr<Spectrum> SpectraTable::ToSpectrum(std::string_view name) const {
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return ToSpectrum(int(i));
    std::string all;
    for (const std::string& n : names) all += (all.empty() ? "" : ", ") + n;
    return NotFoundError("no spectrum column '{}' (columns: {})", name, all);
}

Spectrum SpectraTable::ToSpectrum(int index) const {
    NAVE_CHECK(index >= 0 && size_t(index) < columns.size()) << "column " << index;
    return Spectrum::FromPiecewiseLinearOrDie(lambda_nm, columns[size_t(index)]);
}

}  // namespace nave
