// Materials: dispersion, Beer absorption, thin glass from measured transmittance, built-in names.

#include "src/render/scene/materials/materials.h"

#include <gtest/gtest.h>

#include <cmath>

#include "src/render/scene/materials/ior.h"

namespace nave {
namespace {

TEST(MaterialsTest, DispersiveGlassTerminatesSecondaryWavelengths) {
    DielectricMaterial bk7{Bk7Index(), Spectrum::Constant(0.f)};
    SampledWavelengths lambda = SampledWavelengths::SampleVisible(0.42f);
    Bxdf b = bk7.GetBxdf(lambda);
    EXPECT_TRUE(lambda.SecondaryTerminated());
    const auto& d = std::get<DielectricBxdf>(b.variant());
    EXPECT_FLOAT_EQ(d.eta(), Bk7Index().Evaluate(lambda.lambda_nm(0)));

    DielectricMaterial constant{Spectrum::Constant(1.5f), Spectrum::Constant(0.f)};
    SampledWavelengths lambda2 = SampledWavelengths::SampleVisible(0.42f);
    constant.GetBxdf(lambda2);
    EXPECT_FALSE(lambda2.SecondaryTerminated());
}

// Dispersion: blue refracts more than red through BK7 (n_F > n_C).
TEST(MaterialsTest, BlueBendsMoreThanRed) {
    Vec3f wo = Normalize(Vec3f(0.6f, 0.f, 0.8f));
    auto refracted_sin = [&](float lambda_nm) {
        DielectricBxdf b(Bk7Index().Evaluate(lambda_nm));
        std::optional<BsdfSample> s =
            b.Sample(wo, 0.999f, Point2f(), SampledWavelengths::SampleUniform(0.5f));
        EXPECT_TRUE(s && s->IsTransmission());
        return std::sqrt(Sin2Theta(s->wi));
    };
    EXPECT_LT(refracted_sin(450.f), refracted_sin(650.f));
}

// Beer-Lambert: T = exp(-α d) (Beer 1852).
TEST(MaterialsTest, BeerAbsorption) {
    DielectricMaterial m{Spectrum::Constant(1.5f), Spectrum::Constant(2.f)};
    SampledWavelengths lambda = SampledWavelengths::SampleUniform(0.1f);
    EXPECT_NEAR(m.Transmittance(0.5f, lambda)[2], std::exp(-1.f), 1e-6f);
    EXPECT_NEAR(m.Transmittance(0.f, lambda)[0], 1.f, 1e-7f);
    // Clear soda-lime glass: 4 mm absorbs about 2 % in the green (Rubin 1985 κ ≈ 2.2e-7 at 550 nm).
    float a550 = SodaLimeAbsorptionPerMetre().Evaluate(550.f);
    EXPECT_NEAR(a550, 4 * M_PI * 2.2e-7 / 550e-9, 0.05f);
    EXPECT_NEAR(std::exp(-a550 * 0.004f), 0.980f, 0.002f);
}

// A pane built from a measured total transmittance reproduces it at normal incidence.
TEST(MaterialsTest, ThinGlassFromTotalTransmittanceRoundTrip) {
    Spectrum measured =
        Spectrum::FromFunction([](double l) { return 0.05 + 0.8 * (l - 360) / 470; });
    ThinGlassMaterial pane =
        ThinGlassMaterial::FromTotalTransmittance(Spectrum::Constant(1.5f), measured);
    for (float u : {0.05f, 0.3f, 0.6f, 0.95f}) {
        SampledWavelengths lambda = SampledWavelengths::SampleUniform(u);
        Bxdf b = pane.GetBxdf(lambda);
        SampledSpectrum r, t;
        std::get<ThinDielectricBxdf>(b.variant()).ReflectanceTransmittance(1.f, &r, &t);
        for (int i = 0; i < kNumWavelengths; ++i)
            EXPECT_NEAR(t[i], measured.Evaluate(lambda.lambda_nm(i)), 1e-4f) << lambda.lambda_nm(i);
    }
    // Above the lossless maximum (1-R)/(1+R) the pane is simply clear.
    EXPECT_EQ(ThinGlassMaterial::InternalFromTotalTransmittance(0.99f, 1.5f), 1.f);
    EXPECT_EQ(ThinGlassMaterial::InternalFromTotalTransmittance(0.f, 1.5f), 0.f);
    // The texture hook replaces τ at this hit.
    SampledWavelengths lambda = SampledWavelengths::SampleUniform(0.5f);
    SampledSpectrum opaque(0.f);
    Bxdf b = pane.GetBxdf(lambda, &opaque);
    SampledSpectrum r, t;
    std::get<ThinDielectricBxdf>(b.variant()).ReflectanceTransmittance(1.f, &r, &t);
    EXPECT_EQ(t[0], 0.f);
}

// glass_grisaille: a 3 mm pane of Rubin's (1985) measured green soda-lime glass. Its total normal
// transmittance is the slab's (1-R)²τ/(1-R²τ²) with R = ((n-1)/(n+1))² and τ = exp(-4πk d/λ), here
// from Rubin's tabulated k and his fit for n, written out at three wavelengths: the iron's Fe²⁺
// band makes the red pass a sixth less than the blue-green.
TEST(MaterialsTest, GrisailleIsRubinsMeasuredGreenGlass) {
    StatusOr<Material> m = BuiltinMaterial("glass_grisaille");
    ASSERT_TRUE(m.ok()) << m.status().ToString();
    const auto& pane = std::get<ThinGlassMaterial>(*m);
    struct Row {
        float lambda_nm;
        double k;
    };
    for (Row row : {Row{450.f, 9.902e-7}, Row{550.f, 1.169e-6}, Row{700.f, 5.363e-6}}) {
        double l_um = row.lambda_nm / 1000.0;
        double n = 1.5130 - 0.003169 * l_um * l_um + 0.003962 / (l_um * l_um);
        double r = (n - 1) * (n - 1) / ((n + 1) * (n + 1));
        double tau = std::exp(-4 * M_PI * row.k * 0.003 / (row.lambda_nm * 1e-9));
        double total = (1 - r) * (1 - r) * tau / (1 - r * r * tau * tau);
        EXPECT_NEAR(pane.internal_transmittance.Evaluate(row.lambda_nm), tau, 1e-4)
            << row.lambda_nm;
        // All four wavelengths within a thousandth of a nanometre of the table's.
        SampledWavelengths lambda =
            SampledWavelengths::SampleUniform(0.f, row.lambda_nm, row.lambda_nm + 1e-3f);
        Bxdf b = GetBxdf(*m, lambda);
        SampledSpectrum refl, trans;
        std::get<ThinDielectricBxdf>(b.variant()).ReflectanceTransmittance(1.f, &refl, &trans);
        EXPECT_NEAR(trans[0], total, 2e-4) << row.lambda_nm;
    }
    EXPECT_LT(pane.internal_transmittance.Evaluate(700.f),
              0.85f * pane.internal_transmittance.Evaluate(500.f));
}

TEST(MaterialsTest, BuiltinMaterials) {
    for (const std::string& name : BuiltinMaterialNames()) {
        StatusOr<Material> m = BuiltinMaterial(name);
        ASSERT_TRUE(m.ok()) << name << ": " << m.status().ToString();
        SampledWavelengths lambda = SampledWavelengths::SampleVisible(0.37f);
        Bxdf b = GetBxdf(*m, lambda);
        EXPECT_NE(b.Flags(), 0) << name;
    }
    StatusOr<Material> bad = BuiltinMaterial("marble_pink");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.status().code(), StatusCode::kNotFound);
    EXPECT_NE(bad.status().message().find("limestone"), std::string::npos);
    // Blue glass passes more blue than red light; red glass the opposite.
    auto t_at = [](const char* name, float l) {
        StatusOr<Material> m = BuiltinMaterial(name);
        return std::get<ThinGlassMaterial>(m.value()).internal_transmittance.Evaluate(l);
    };
    EXPECT_GT(t_at("glass_blue", 450.f), 5 * t_at("glass_blue", 600.f));
    EXPECT_GT(t_at("glass_red", 650.f), 100 * t_at("glass_red", 500.f));
}

}  // namespace
}  // namespace nave
