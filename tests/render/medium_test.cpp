// Participating media ([medium]): the Henyey-Greenstein phase function, Beer-Lambert transmittance,
// the spectral free-flight estimator, and renders against closed forms (an absorbing slab, single
// scattering of a directional light, a white furnace filled with an albedo-1 medium).

#include "src/render/scene/media/medium.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "chi2.h"
#include "render_test_util.h"
#include "src/core/progress.h"
#include "src/core/sampling.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/scene/media/henyey_greenstein.h"
#include "src/render/transport/medium_flight.h"

namespace nave::render {
namespace {

using testing::MeanY;
using testing::Render;

constexpr float kInf = std::numeric_limits<float>::infinity();

class MediumRenderTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
};

// ∫ p dω = 1 and ∫ cos θ p dω = g (the definition of g; Henyey & Greenstein 1941): a midpoint
// quadrature in cos θ (the phase function does not depend on φ).
TEST(HenyeyGreensteinTest, IsNormalisedWithMeanCosineG) {
    for (float g : {-0.8f, -0.3f, 0.f, 0.5f, 0.9f}) {
        const HenyeyGreenstein hg(g);
        const int n = 200000;
        double total = 0, mean_cos = 0;
        for (int i = 0; i < n; ++i) {
            const double mu = -1 + (i + 0.5) * 2.0 / n;
            const double p = hg.Eval(float(mu)) * 2 * M_PI * (2.0 / n);
            total += p;
            mean_cos += mu * p;
        }
        EXPECT_NEAR(total, 1.0, 1e-4) << "g " << g;
        EXPECT_NEAR(mean_cos, g, 1e-3) << "g " << g;
    }
}

TEST(HenyeyGreensteinTest, SamplesItsOwnDensityChiSquare) {
    uint64_t seed = 11;
    for (float g : {-0.7f, 0.f, 0.3f, 0.85f}) {
        const HenyeyGreenstein hg(g);
        const Vec3f dir = Normalize(Vec3f(0.3f, -0.5f, 0.8f));
        auto sample = [&](float u1, float u2, float) -> std::optional<Vec3f> {
            const PhaseSample s = hg.Sample(dir, Point2f(u1, u2));
            // The density it reports is the phase function's.
            EXPECT_NEAR(s.pdf, hg.Eval(Dot(dir, s.wi)), 1e-3f * s.pdf);
            return s.wi;
        };
        auto pdf = [&](const Vec3f& w) { return hg.Eval(Dot(dir, w)); };
        const nave::testing::Chi2Result r =
            nave::testing::Chi2Test(sample, pdf, seed++, 200000, 12, 5e-4);
        EXPECT_TRUE(r.passed) << "g " << g << ": " << r.message;
    }
}

Spectrum Rising() {
    // A coefficient that varies with wavelength: 0.2 m^-1 at 360 nm to 2.0 m^-1 at 830 nm.
    return Spectrum::FromFunction([](double nm) { return 0.2 + 1.8 * (nm - 360) / 470; });
}

// Beer-Lambert: exp(-σt ℓ) with ℓ the length inside the box.
TEST(MediumTest, TransmittanceIsBeerLambertOverTheLengthInsideTheBox) {
    const Medium m(std::make_shared<BoxDensity>(Bounds3f({0, 0, 0}, {1, 1, 1})),
                   Spectrum::Constant(0.25f), Rising(), 0.f);
    const SampledWavelengths lambda = SampledWavelengths::SampleVisible(0.37f);
    const SampledSpectrum sigma_t = m.SigmaT(lambda);
    const Vec3f o(-1, 0.5f, 0.5f), d(1, 0, 0);
    const DensityField& box = *m.DensityIn(nullptr);
    const auto transmittance = [&](const Vec3f& origin, float t_max) {
        return m.Transmittance(box.Integral(origin, d, 0, t_max), lambda);
    };
    const SampledSpectrum through = transmittance(o, kInf);
    const SampledSpectrum half = transmittance(o, 1.5f);
    for (int i = 0; i < kNumWavelengths; ++i) {
        EXPECT_NEAR(through[i], std::exp(-sigma_t[i] * 1.f), 1e-6f);
        EXPECT_NEAR(half[i], std::exp(-sigma_t[i] * 0.5f), 1e-6f);
        EXPECT_GT(sigma_t[i], 0.25f);
    }
    // A ray beside the box, and one that stops before it, cross none of it.
    EXPECT_EQ(transmittance(Vec3f(-1, 2, 0.5f), kInf), SampledSpectrum(1.f));
    EXPECT_EQ(transmittance(o, 0.9f), SampledSpectrum(1.f));
    // Diagonally through a corner region: the slab test's length.
    EXPECT_NEAR(box.Integral(Vec3f(-0.5f, -0.5f, 0.5f), Normalize(Vec3f(1, 1, 0)), 0, kInf),
                std::sqrt(2.f), 1e-5f);
    // From t = 1.25 on, half the box is left.
    EXPECT_NEAR(box.Integral(o, d, 1.25f, kInf), 0.75f, 1e-6f);
}

// The free-flight estimator at every wavelength, with an extinction that varies with wavelength:
// scatterings weighted by ScatterWeight estimate ∫0^L σs e^(-σt s) ds = σs/σt (1 - e^(-σt L)), rays
// through weighted by NoScatterWeight estimate e^(-σt L), whichever wavelength drew the distance.
// Each ray flies in two stretches, as across two bricks, carrying its flight's depth between them.
TEST(MediumFlightTest, WeightsEstimateScatteringAndTransmittanceAtEveryWavelength) {
    const float length = 1.5f;
    const Medium m(std::make_shared<BoxDensity>(Bounds3f({0, -1, -1}, {length, 1, 1})),
                   Spectrum::Constant(0.1f), Rising(), 0.f);
    const DensityField& box = *m.DensityIn(nullptr);
    RayRecord base;
    base.origin = Vec3f(-0.5f, 0, 0);
    base.dir = Vec3f(1, 0, 0);
    base.t_max = kInf;
    base.lambda = SampledWavelengths::SampleVisible(0.61f);
    const SampledSpectrum sigma_t = m.SigmaT(base.lambda), sigma_s = m.SigmaS(base.lambda);
    nave::testing::Pcg32 rng(5);
    const int n = 400000;
    const float split = 1.2f;  // where the first stretch ends
    SampledSpectrum scattered, through;
    int scatterings = 0;
    for (int k = 0; k < n; ++k) {
        RayRecord r = base;
        r.flight_depth = 0;
        const float u_choice = rng.NextFloat(), u_distance = rng.NextFloat();
        const float depth = FlightDepth(m, r.lambda, u_choice, u_distance);
        float t = Fly(&box, depth, 0, split, &r);
        if (std::isinf(t)) {
            EXPECT_NEAR(r.flight_depth, split - 0.5f, 1e-6f);
            t = Fly(&box, depth, split, kInf, &r);
        }
        if (!std::isinf(t)) {
            ++scatterings;
            EXPECT_GE(t, 0.5f);
            EXPECT_LE(t, 0.5f + length);
            // The depth it aimed at is the density's integral up to where it scatters.
            EXPECT_NEAR(box.Integral(r.origin, r.dir, 0, t), depth, 1e-5f);
            scattered += ScatterWeight(m, r.lambda, depth);
        } else {
            EXPECT_NEAR(r.flight_depth, length, 1e-5f);
            through += NoScatterWeight(m, r.lambda, r.flight_depth);
        }
    }
    EXPECT_GT(scatterings, n / 10);
    for (int i = 0; i < kNumWavelengths; ++i) {
        const float t = std::exp(-sigma_t[i] * length);
        EXPECT_NEAR(through[i] / n, t, 0.01f) << "wavelength " << base.lambda[i];
        EXPECT_NEAR(scattered[i] / n, sigma_s[i] / sigma_t[i] * (1 - t), 0.01f)
            << "wavelength " << base.lambda[i];
    }
}

// A field shared out among cells (a grid cut into bricks): the shares' walks along a ray, one cell
// after the other, add up to the whole's, and reach a target where the whole does.
TEST(MediumFlightTest, CellSharesOfAFieldAddUpToTheWhole) {
    auto whole = std::make_shared<BoxDensity>(Bounds3f({0, -1, -1}, {3, 1, 1}));
    const Bounds3f left({-1, -2, -2}, {1.25f, 2, 2}), right({1.25f, -2, -2}, {4, 2, 2});
    const CellShare a(whole, left, 2.f), b(whole, right, 2.f);
    const Vec3f o(-0.5f, 0.1f, 0), d = Normalize(Vec3f(1, 0.1f, 0));
    const float total = 2 * whole->Integral(o, d, 0, kInf);
    EXPECT_NEAR(a.Integral(o, d, 0, kInf) + b.Integral(o, d, 0, kInf), total, 1e-5f);
    EXPECT_NEAR(a.Integral(o, d, 0, kInf), 2 * 1.25f / d.x, 1e-5f);
    const float target = 0.8f * total;
    const float t_whole = whole->Reach(o, d, 0, kInf, target / 2);
    EXPECT_TRUE(std::isinf(a.Reach(o, d, 0, kInf, target)));
    const float t = b.Reach(o, d, 0, kInf, target - a.Integral(o, d, 0, kInf));
    EXPECT_NEAR(t, t_whole, 1e-5f);
}

// An emitter seen through a slab of pure absorber 1 m thick: dimmed by e^(-σa), exactly (the same
// paths and wavelengths as without the slab; absorption is a weight, not a chance).
TEST_F(MediumRenderTest, AnAbsorbingSlabDimsWhatIsBehindItByBeerLambert) {
    const store::BrickMesh mesh = testing::LampMesh();
    const std::string config = testing::kLampConfig;
    const auto clear = Render(mesh, {"lamp"}, config, 2);
    const auto hazy = Render(mesh, {"lamp"}, config + R"(
[medium]
box_min = [1, -1, -1]
box_max = [2, 1, 1]
sigma_a = 0.7
)",
                             2);
    ASSERT_TRUE(clear && hazy);
    // The view's rays lie within 0.5° of the slab's normal: up to 4e-5 longer inside it.
    EXPECT_NEAR(MeanY(*hazy->film) / MeanY(*clear->film), std::exp(-0.7), 5e-5);
}

// extinction and albedo are σt and σs / σt: the same image as the coefficients they stand for.
TEST_F(MediumRenderTest, ExtinctionAndAlbedoAreTheCoefficientsTheyStandFor) {
    store::BrickMesh mesh;
    AppendSphere(&mesh, {0, 0, 0}, 1.0f, 12, 24, 0, /*inward=*/true);
    const std::string base = fmt::format(fmt::runtime(testing::kFurnace), "path");
    const auto coefficients =
        Render(mesh, {"shell"}, base + "[medium]\nsigma_s = 0.8\nsigma_a = 0.2\n", 1);
    const auto albedo =
        Render(mesh, {"shell"}, base + "[medium]\nextinction = 1.0\nalbedo = 0.8\n", 1);
    ASSERT_TRUE(coefficients && albedo);
    EXPECT_LT(MeanY(*coefficients->film), 0.95);  // the medium absorbs
    EXPECT_LT(testing::MaxRelativeDifference(*coefficients->film, *albedo->film), 1e-6);
}

// A directional light of irradiance E from above into a slab of medium, seen side-on along a
// narrow view: single scattering (max_depth 1) gives L = E σs p(90°) e^(-σt h) (1 - e^(-σt D)) /
// σt, h the depth below the slab's top the light crosses, D the slab's length along the view.
TEST_F(MediumRenderTest, SingleScatteringOfADirectionalLightMatchesItsClosedForm) {
    store::BrickMesh mesh;
    AppendQuad(&mesh, {10, 0, 0}, {0, 0, 1}, {0, 1, 0}, 2, 0);  // black, behind the slab
    const float sigma_s = 0.3f, sigma_a = 0.1f, g = 0.4f, e = 2.f, h = 1.f, d = 2.f;
    const auto t = Render(mesh, {"backdrop"},
                          fmt::format(R"(
[camera]
position = [0, 0, 0]
look_at = [1, 0, 0]
fov_deg = 1
resolution = [4, 4]
[materials.backdrop]
type = "black"
[[lights]]
type = "directional"
direction = [0, 0, -1]
irradiance = {}
[medium]
box_min = [1, -1, -5]
box_max = [{}, 1, {}]
sigma_s = {}
sigma_a = {}
g = {}
[render]
mode = "path"
spp = 256
max_depth = 1
)",
                                      e, 1 + d, h, sigma_s, sigma_a, g),
                          2);
    ASSERT_TRUE(t);
    const float sigma_t = sigma_s + sigma_a;
    const double expected = e * sigma_s * HenyeyGreenstein(g).Eval(0.f) * std::exp(-sigma_t * h) *
                            (1 - std::exp(-sigma_t * d)) / sigma_t;
    EXPECT_NEAR(MeanY(*t->film), expected, 0.02 * expected);
}

// Inside a closed sphere of albedo 0.5 emitting 0.5 (radiance 1 everywhere, render_test.cpp's
// furnace) a medium that scatters and does not absorb changes nothing: L stays 1. In photon mode
// too: photons fly and scatter in the medium (their power weighted as paths' throughput is), and
// camera paths scatter in it and gather the photons where they reach a surface.
TEST_F(MediumRenderTest, AWhiteFurnaceFilledWithAScatteringMediumStaysAtOne) {
    for (const auto& [mode, tolerance] : {std::pair{"path", 0.03}, {"photon", 0.02}}) {
        const auto t = Render(testing::FurnaceMesh(), {"shell"},
                              fmt::format(fmt::runtime(testing::kFurnace), mode) + R"(
[medium]
sigma_s = 1.5
g = 0.5
)",
                              2);
        ASSERT_TRUE(t);
        EXPECT_NEAR(MeanY(*t->film), 1.0, tolerance) << mode;
    }
}

TEST(MediumConfigTest, BadMediaAreNamed) {
    auto error = [](const std::string& medium, const std::string& mode = "path") {
        return testing::ConfigError(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[medium]\n" + medium +
                "\n[render]\nmode = \"" + mode + "\"\n",
            "haze.toml");
    };
    EXPECT_NE(error("g = 0.3").find("missing 'sigma_s' and 'sigma_a'"), std::string::npos);
    EXPECT_NE(error("sigma_s = 0.1\nbox_min = [0, 0, 0]").find("both box_min and box_max"),
              std::string::npos);
    EXPECT_NE(error("sigma_s = 0.1\nbox_min = [0, 0, 0]\nbox_max = [1, -1, 1]")
                  .find("box_min must be below box_max"),
              std::string::npos);
    EXPECT_NE(error("sigma_s = 0.1\ng = 1").find("medium.g"), std::string::npos);
    EXPECT_NE(error("sigma_s = 0.1\ndensity = 3").find("density"), std::string::npos);
    EXPECT_NE(error("sigma_s = 0.1\nextinction = 0.2").find("not both"), std::string::npos);
    EXPECT_NE(error("extinction = 0.2").find("go together"), std::string::npos);
    EXPECT_EQ(error("sigma_s = 0.1\nsigma_a = 0.01\ng = 0.5"), "");
    EXPECT_EQ(error("extinction = 0.02\nalbedo = 0.9"), "");
}

TEST_F(MediumRenderTest, MediaBeyondTheModelInPhotonModeAndNegativeCoefficientsAreRefused) {
    store::BrickMesh mesh;
    AppendQuad(&mesh, {3, 0, 0}, {0, 0, 2}, {0, 2, 0}, 2, 0);
    auto build_error = [&](const std::string& medium, const std::string& mode) {
        StatusOr<SceneConfig> config = ParseSceneConfig(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[materials.default]\n[medium]\n" +
                medium + "\n[render]\nmode = \"" + mode + "\"\n",
            "haze.toml");
        EXPECT_TRUE(config.ok()) << config.status().message();
        if (!config.ok()) return std::string();
        StatusOr<std::unique_ptr<testing::TestScene>> scene = testing::BuildTestScene(
            testing::GridSource(mesh, testing::NamedMaterials({"default"}), Vec3i(1, 1, 1)),
            *config);
        return scene.ok() ? std::string() : std::string(scene.status().message());
    };
    // Photon mode: inside the model's box (its default), not beyond it.
    EXPECT_EQ(build_error("sigma_s = 0.1", "photon"), "");
    const std::string beyond =
        build_error("sigma_s = 0.1\nbox_min = [0, -1, -1]\nbox_max = [5, 1, 1]", "photon");
    EXPECT_NE(beyond.find("beyond the model's box"), std::string::npos) << beyond;
    EXPECT_NE(beyond.find("haze.toml"), std::string::npos) << beyond;
    EXPECT_NE(build_error("sigma_s = -0.1", "path").find("medium.sigma_s is -0.1"),
              std::string::npos);
    EXPECT_NE(build_error("extinction = 0.1\nalbedo = 1.2", "path").find("medium.albedo is 1.2"),
              std::string::npos);
    EXPECT_EQ(build_error("sigma_s = 0.1", "path"), "");
}

}  // namespace
}  // namespace nave::render
