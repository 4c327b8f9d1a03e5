// Tests of spectra, wavelength sampling and spectral CSV parsing.

#include "src/core/spectrum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "src/core/color.h"
#include "src/core/illuminant.h"
#include "src/core/spectrum_data.h"

namespace nave {
namespace {

TEST(SampledSpectrumTest, Arithmetic) {
    SampledSpectrum a({1.f, 2.f, 3.f, 4.f});
    SampledSpectrum b(2.f);
    EXPECT_EQ((a + b)[3], 6.f);
    EXPECT_EQ((a - b)[0], -1.f);
    EXPECT_EQ((a * b)[2], 6.f);
    EXPECT_EQ((a / b)[1], 1.f);
    EXPECT_EQ((2.f * a)[3], 8.f);
    EXPECT_FLOAT_EQ(a.Average(), 2.5f);
    EXPECT_EQ(a.MaxValue(), 4.f);
    EXPECT_EQ(a.MinValue(), 1.f);
    EXPECT_TRUE(SampledSpectrum().IsZero());
    EXPECT_FALSE(a.IsZero());
    SampledSpectrum z({1.f, 0.f, 2.f, 0.f});
    SampledSpectrum q = SafeDiv(a, z);
    EXPECT_EQ(q[0], 1.f);
    EXPECT_EQ(q[1], 0.f);
    EXPECT_EQ(q[2], 1.5f);
    EXPECT_FLOAT_EQ(Exp(SampledSpectrum(1.f))[0], std::exp(1.f));
}

TEST(SampledWavelengthsTest, VisiblePdfIntegratesToOne) {
    // Trapezoid rule on a 0.01 nm grid over [360, 830].
    double sum = 0;
    const double h = 0.01;
    for (double l = kLambdaMinNm; l < kLambdaMaxNm; l += h)
        sum += 0.5 * h * (VisibleWavelengthsPdf(float(l)) + VisibleWavelengthsPdf(float(l + h)));
    EXPECT_NEAR(sum, 1.0, 1e-4);
    EXPECT_EQ(VisibleWavelengthsPdf(300.f), 0.f);
    EXPECT_EQ(VisibleWavelengthsPdf(900.f), 0.f);
}

TEST(SampledWavelengthsTest, SampleVisibleInvertsTheCdf) {
    // The fraction of samples below λ must equal the integral of the pdf up to λ.
    for (float u : {0.f, 0.1f, 0.37f, 0.5f, 0.9f, 0.999f}) {
        float l = SampleVisibleWavelengths(u);
        double cdf = 0;
        const double h = 0.01;
        for (double x = kLambdaMinNm; x < l; x += h)
            cdf += h * VisibleWavelengthsPdf(float(x + 0.5 * h));
        EXPECT_NEAR(cdf, u, 2e-4) << "u " << u << " lambda " << l;
    }
}

// The CDF gives back the number a wavelength was drawn with (to float precision), and agrees with
// the pdf's integral.
TEST(SampledWavelengthsTest, TheCdfInvertsSampling) {
    for (float u : {0.f, 0.013f, 0.25f, 0.5f, 0.77f, 0.999f}) {
        EXPECT_NEAR(VisibleWavelengthsCdf(SampleVisibleWavelengths(u)), u, 2e-6f) << u;
    }
    double cdf = 0;
    const double h = 0.01;
    for (double x = kLambdaMinNm; x < 600; x += h)
        cdf += h * VisibleWavelengthsPdf(float(x + 0.5 * h));
    EXPECT_NEAR(VisibleWavelengthsCdf(600.f), cdf, 2e-4);
    EXPECT_NEAR(VisibleWavelengthsCdf(kLambdaMinNm), 0.f, 1e-6f);
    EXPECT_NEAR(VisibleWavelengthsCdf(kLambdaMaxNm), 1.f, 1e-6f);
}

TEST(SampledWavelengthsTest, StratifiedRotationsAndPdf) {
    SampledWavelengths w = SampledWavelengths::SampleVisible(0.3f);
    for (int i = 0; i < kNumWavelengths; ++i) {
        EXPECT_GE(w.lambda_nm(i), kLambdaMinNm);
        EXPECT_LE(w.lambda_nm(i), kLambdaMaxNm);
        EXPECT_FLOAT_EQ(w.Pdf()[i], VisibleWavelengthsPdf(w.lambda_nm(i)));
    }
    EXPECT_FLOAT_EQ(w.lambda_nm(1), SampleVisibleWavelengths(0.55f));
    EXPECT_FALSE(w.SecondaryTerminated());
    float hero_pdf = w.Pdf()[0];
    w.TerminateSecondary();
    EXPECT_TRUE(w.SecondaryTerminated());
    EXPECT_FLOAT_EQ(w.Pdf()[0], hero_pdf / kNumWavelengths);
    for (int i = 1; i < kNumWavelengths; ++i) EXPECT_EQ(w.Pdf()[i], 0.f);

    SampledWavelengths uni = SampledWavelengths::SampleUniform(0.9f, 400.f, 700.f);
    EXPECT_FLOAT_EQ(uni.lambda_nm(0), 670.f);
    EXPECT_FLOAT_EQ(uni.lambda_nm(1), 445.f);  // 670 + 75 = 745 wraps to 400 + 45
    EXPECT_FLOAT_EQ(uni.lambda_nm(2), 520.f);
    EXPECT_FLOAT_EQ(uni.Pdf()[2], 1.f / 300.f);
}

// The film's estimator of ∫ȳ·D65 / ∫ȳ with importance-sampled wavelengths converges to the exact
// sum.
TEST(SampledWavelengthsTest, EstimatorOfYOfD65Converges) {
    const Spectrum& d65 = IlluminantD65();
    double exact = SpectrumToXYZ(d65).y;
    for (bool terminate : {false, true}) {
        const int n = 100000;
        double y = 0;
        for (int i = 0; i < n; ++i) {
            SampledWavelengths w = SampledWavelengths::SampleVisible((i + 0.5f) / n);
            if (terminate) w.TerminateSecondary();
            y += SampledToXYZ(d65.Sample(w), w).y;
        }
        y /= n;
        EXPECT_NEAR(y / exact, 1.0, 1e-3) << "terminate " << terminate;
    }
}

TEST(SpectrumTest, EvaluateInterpolatesAndIsZeroOutside) {
    StatusOr<Spectrum> s = Spectrum::FromPiecewiseLinear({400, 500, 600}, {0.0, 1.0, 0.5});
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    EXPECT_FLOAT_EQ(s->Evaluate(450.f), 0.5f);
    EXPECT_FLOAT_EQ(s->Evaluate(550.5f), 0.7475f);
    EXPECT_FLOAT_EQ(s->Evaluate(380.f), 0.f);   // end value held
    EXPECT_FLOAT_EQ(s->Evaluate(700.f), 0.5f);  // end value held
    EXPECT_EQ(s->Evaluate(359.f), 0.f);
    EXPECT_EQ(s->Evaluate(831.f), 0.f);
    EXPECT_FALSE(Spectrum::FromPiecewiseLinear({500, 400}, {1, 1}).ok());
    EXPECT_FALSE(Spectrum::FromPiecewiseLinear({500}, {1, 1}).ok());
    EXPECT_TRUE(Spectrum::Constant(2.f).IsConstant());
    EXPECT_FLOAT_EQ((Spectrum::Constant(2.f) * Spectrum::Constant(3.f)).Evaluate(555.f), 6.f);
}

// Stefan-Boltzmann: π ∫ B(λ, T) dλ = σ T⁴, σ = 5.670374419e-8 W m⁻² K⁻⁴ (CODATA 2018).
TEST(SpectrumTest, PlanckIntegratesToStefanBoltzmann) {
    const double t = 5778.0;
    double sum = 0;
    for (double l = 10.0; l < 200000.0; l += 0.5) sum += PlanckRadiance(l + 0.25, t) * 0.5;
    EXPECT_NEAR(M_PI * sum / (5.670374419e-8 * std::pow(t, 4)), 1.0, 1e-4);
    Spectrum bb = Spectrum::Blackbody(5000.0);
    // Wien peak at 2897.77/5000 µm = 579.55 nm.
    EXPECT_NEAR(bb.Evaluate(579.55f), 1.f, 1e-5f);
    EXPECT_LT(bb.Evaluate(500.f), 1.f);
    EXPECT_LT(bb.Evaluate(650.f), 1.f);
}

TEST(SpectrumTest, DaylightSeriesMatchesD65Table) {
    // CIE 15:2004: D65 is the daylight of CCT 6500 × 1.4388/1.4380 K ≈ 6504 K; the computed series
    // matches the tabulated D65 to the table's rounding (M1, M2 rounded to 3 decimals).
    Spectrum d = Spectrum::CieIlluminantD(6500.0 * 1.4388 / 1.4380);
    for (float l = 380.f; l <= 780.f; l += 5.f)
        EXPECT_NEAR(d.Evaluate(l), IlluminantD65().Evaluate(l), 0.05f) << l;
    EXPECT_FLOAT_EQ(d.Evaluate(560.f), 100.f);
}

TEST(SpectraCsvTest, ParsesHeaderCommentsAndColumns) {
    StatusOr<SpectraTable> t = ParseSpectraCsv(
        "# measured\nwavelength_nm, red ,blue\n400,0.1,0.9  # "
        "comment\n\n500;0.2;0.8\n600\t0.3\t0.7\n",
        "x.csv");
    ASSERT_TRUE(t.ok()) << t.status().ToString();
    ASSERT_EQ(t->names.size(), 2u);
    EXPECT_EQ(t->names[0], "red");
    EXPECT_EQ(t->lambda_nm.size(), 3u);
    EXPECT_DOUBLE_EQ(t->columns[1][2], 0.7);
    StatusOr<Spectrum> blue = t->ToSpectrum("blue");
    ASSERT_TRUE(blue.ok());
    EXPECT_FLOAT_EQ(blue->Evaluate(450.f), 0.85f);
    EXPECT_EQ(t->ToSpectrum("green").status().code(), StatusCode::kNotFound);
}

TEST(SpectraCsvTest, ByteOrderMarkAndCrLf) {
    StatusOr<SpectraTable> t = ParseSpectraCsv(
        "\xEF\xBB\xBF"
        "400,0.1\r\n500,0.2\r\n",
        "excel.csv");
    ASSERT_TRUE(t.ok()) << t.status().ToString();
    EXPECT_EQ(t->lambda_nm.size(), 2u);
    EXPECT_DOUBLE_EQ(t->columns[0][1], 0.2);
    EXPECT_FALSE(ParseSpectraCsv("400,nan\n", "n.csv").ok());
}

TEST(SpectraCsvTest, ErrorsNameFileAndLine) {
    auto msg = [](std::string_view text) {
        StatusOr<SpectraTable> t = ParseSpectraCsv(text, "bad.csv");
        EXPECT_FALSE(t.ok());
        return t.ok() ? std::string() : t.status().message();
    };
    EXPECT_EQ(msg("400,1\n500,1,2\n"), "bad.csv:2: expected 2 columns, found 3");
    EXPECT_EQ(msg("400,1\n500,x\n"), "bad.csv:2: column 2: expected a number, found 'x'");
    EXPECT_EQ(msg("500,1\n400,1\n"),
              "bad.csv:2: wavelengths must increase, found 400 nm after 500 nm");
    EXPECT_EQ(msg("# nothing\n"), "bad.csv: no spectral data rows (wavelength_nm,value,...)");
    EXPECT_EQ(msg("nm,v\n400,1\nfoo,2\n"), "bad.csv:3: expected a wavelength in nm, found 'foo'");
    EXPECT_EQ(msg("400\n"),
              "bad.csv:1: expected a wavelength and at least one value, found 1 column");
}

TEST(SpectraCsvTest, LoadFromFileAndMissingFile) {
    std::filesystem::path p = std::filesystem::temp_directory_path() / "nave_spectrum_test.csv";
    {
        std::ofstream f(p);
        f << "nm,r\n380,0.5\n730,0.5\n";
    }
    StatusOr<SpectraTable> t = LoadSpectraCsv(p);
    ASSERT_TRUE(t.ok()) << t.status().ToString();
    EXPECT_EQ(t->columns[0].size(), 2u);
    std::filesystem::remove(p);
    EXPECT_FALSE(LoadSpectraCsv(p).ok());
}

TEST(EmbeddedDataTest, AllCompiledInFilesParse) {
    std::vector<std::string_view> names = EmbeddedDataFileNames();
    EXPECT_GE(names.size(), 3u);
    for (std::string_view n : names) {
        StatusOr<SpectraTable> t = ParseSpectraCsv(EmbeddedDataFile(n), n);
        EXPECT_TRUE(t.ok()) << t.status().ToString();
    }
    EXPECT_TRUE(EmbeddedDataFile("no_such_file.csv").empty());
}

}  // namespace
}  // namespace nave
