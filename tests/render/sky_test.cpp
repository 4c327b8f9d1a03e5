// Preetham et al. (1999) sky: structure of the model and consistency of its spectra.

#include "src/render/scene/sun/sky.h"

#include <gtest/gtest.h>

#include <cmath>

#include "src/core/color.h"

namespace nave {
namespace {

Vec3f FromAngles(double elevation_deg, double azimuth_deg) {
    double e = elevation_deg * M_PI / 180, a = azimuth_deg * M_PI / 180;
    return Normalize(Vec3f(float(std::cos(e) * std::sin(a)), float(std::cos(e) * std::cos(a)),
                           float(std::sin(e))));
}

TEST(PreethamSkyTest, ZenithAndDistribution) {
    PreethamSky sky(FromAngles(45, 180), 2.5f);
    // The Perez distribution is normalised to the zenith values (Preetham et al. 1999 eq. 3).
    Vec3d z = sky.xyY(Vec3f(0, 0, 1));
    EXPECT_NEAR(z.z, sky.zenith_luminance(), 1e-9 * sky.zenith_luminance());
    EXPECT_NEAR(z.x, sky.zenith_x(), 1e-12);
    // Zenith luminance with the sun 45° high and turbidity 2.5 from Appendix A.2: 5.9 kcd/m²,
    // within the 3-10 kcd/m² measured under clear skies at that solar elevation (CIE 110-1994,
    // Kittler et al. 1997).
    EXPECT_NEAR(sky.zenith_luminance(), 5917.0, 10.0);
    // Zenith chromaticity near the daylight locus, bluish (x < 0.31).
    EXPECT_GT(sky.zenith_x(), 0.22);
    EXPECT_LT(sky.zenith_x(), 0.31);
    // Brighter around the sun than 90° away at the same elevation; symmetric about the sun's
    // vertical.
    EXPECT_GT(sky.xyY(FromAngles(45, 165)).z, sky.xyY(FromAngles(45, 90)).z);
    EXPECT_NEAR(sky.xyY(FromAngles(30, 120)).z, sky.xyY(FromAngles(30, 240)).z,
                1e-6 * sky.zenith_luminance());
    // Nothing from below the horizon.
    EXPECT_EQ(sky.xyY(Vec3f(0, 1, -0.1f)).z, 0.0);
    // A hazier sky is brighter at the zenith (more scattering).
    EXPECT_GT(PreethamSky(FromAngles(45, 180), 6.f).zenith_luminance(), sky.zenith_luminance());
}

// The zenith values of Preetham, Shirley & Smits (1999), Appendix A.2, written here as the paper
// prints them: x_z and y_z are the row (T², T, 1) times a 3×4 table times the column (θs³, θs², θs,
// 1) (θs in radians), Y_z = (4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192 kcd/m² with χ = (4/9 −
// T/120)(π − 2θs). Checked at turbidities 2-8 and suns from 10° to 80° high.
TEST(PreethamSkyTest, ZenithValuesFollowThePapersTables) {
    const double x_table[3][4] = {{0.00166, -0.00375, 0.00209, 0},
                                  {-0.02903, 0.06377, -0.03202, 0.00394},
                                  {0.11693, -0.21196, 0.06052, 0.25886}};
    const double y_table[3][4] = {{0.00275, -0.00610, 0.00317, 0},
                                  {-0.04214, 0.08970, -0.04153, 0.00516},
                                  {0.15346, -0.26756, 0.06670, 0.26688}};
    auto product = [](const double(&m)[3][4], double t, double th) {
        const double row[3] = {t * t, t, 1}, col[4] = {th * th * th, th * th, th, 1};
        double v = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) v += row[i] * m[i][j] * col[j];
        return v;
    };
    for (double t : {2.0, 3.0, 5.0, 8.0}) {
        for (double elevation : {10.0, 30.0, 50.0, 80.0}) {
            const double th = (90 - elevation) * M_PI / 180;
            PreethamSky sky(FromAngles(elevation, 135), float(t));
            const double chi = (4.0 / 9 - t / 120) * (M_PI - 2 * th);
            const double yz = ((4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192) * 1000;
            SCOPED_TRACE(testing::Message() << "T " << t << ", sun " << elevation << " deg high");
            // The sun's direction passes through float: its zenith angle within ~1e-7 rad.
            EXPECT_NEAR(sky.zenith_x(), product(x_table, t, th), 1e-6);
            EXPECT_NEAR(sky.zenith_y(), product(y_table, t, th), 1e-6);
            EXPECT_NEAR(sky.zenith_luminance(), yz, 1e-5 * yz);
        }
    }
}

// Against an independent model: the CIE standard clear sky (CIE S 011/E:2003, type 12, "clear, low
// luminance turbidity"), L/L_z = f(γ) φ(θ) / (f(θs) φ(0)) with φ(θ) = 1 + a e^(b / cos θ),
// f(γ) = 1 + c (e^(dγ) − e^(dπ/2)) + e cos² γ, a = −1, b = −0.32, c = 10, d = −3, e = 0.45.
// The two were fitted to different measurements and differ by up to a factor of two near the
// horizon and around the sun (Zotti, Wilkie & Purgathofer 2007 found the same of Preetham's model
// against CIE skies), so the bound is loose: it catches a wrong sign or a swapped coefficient,
// which move the ratio by far more. Measured: radiance ratios 0.50-1.35; the diffuse horizontal
// illuminance over L_z 0.80, 0.88, 1.05 of the CIE sky's with the sun 20°, 40°, 60° high.
TEST(PreethamSkyTest, ShapeAgreesWithTheCieStandardClearSky) {
    auto cie = [](double theta, double gamma, double theta_sun) {
        auto phi = [](double z) { return 1 - std::exp(-0.32 / std::max(std::cos(z), 1e-3)); };
        auto f = [](double g) {
            return 1 + 10 * (std::exp(-3 * g) - std::exp(-3 * M_PI / 2)) +
                   0.45 * std::cos(g) * std::cos(g);
        };
        return f(gamma) * phi(theta) / (f(theta_sun) * phi(0));
    };
    double lo = 1e9, hi = 0;
    for (double sun_elevation : {20.0, 40.0, 60.0}) {
        const Vec3f sun = FromAngles(sun_elevation, 180);
        const double theta_sun = (90 - sun_elevation) * M_PI / 180;
        PreethamSky sky(sun, 2.5f);
        for (double elevation = 10; elevation <= 90; elevation += 10) {
            for (double azimuth = 0; azimuth < 360; azimuth += 30) {
                const Vec3f w = FromAngles(elevation, azimuth);
                const double gamma = std::acos(std::clamp(double(Dot(w, sun)), -1.0, 1.0));
                if (gamma < 5 * M_PI / 180) continue;
                const double ratio = sky.xyY(w).z / sky.zenith_luminance() /
                                     cie((90 - elevation) * M_PI / 180, gamma, theta_sun);
                lo = std::min(lo, ratio);
                hi = std::max(hi, ratio);
                EXPECT_GT(ratio, 0.45)
                    << "sun " << sun_elevation << ", view " << elevation << "/" << azimuth;
                EXPECT_LT(ratio, 1.5)
                    << "sun " << sun_elevation << ", view " << elevation << "/" << azimuth;
            }
        }
        // ∫ L cos θ dω / L_z over the sky (sun's 5° excluded), midpoint rule on a 1° grid.
        double preetham = 0, reference = 0;
        for (int i = 0; i < 90; ++i) {
            for (int j = 0; j < 360; ++j) {
                const double theta = (i + 0.5) * M_PI / 180, az = (j + 0.5) * M_PI / 180;
                const Vec3f w(float(std::sin(theta) * std::cos(az)),
                              float(std::sin(theta) * std::sin(az)), float(std::cos(theta)));
                const double gamma = std::acos(std::clamp(double(Dot(w, sun)), -1.0, 1.0));
                if (gamma < 5 * M_PI / 180) continue;
                const double d = std::cos(theta) * std::sin(theta) * (M_PI / 180) * (M_PI / 180);
                preetham += sky.xyY(w).z / sky.zenith_luminance() * d;
                reference += cie(theta, gamma, theta_sun) * d;
            }
        }
        EXPECT_NEAR(preetham / reference, 1.0, 0.25) << "sun " << sun_elevation;
        std::printf("sun %.0f deg: diffuse horizontal / L_z %.3f (Preetham) %.3f (CIE)\n",
                    sun_elevation, preetham, reference);
    }
    std::printf("radiance ratio Preetham / CIE within [%.3f, %.3f]\n", lo, hi);
}

TEST(PreethamSkyTest, SpectrumReproducesLuminanceAndChromaticity) {
    PreethamSky sky(FromAngles(35, 200), 3.f);
    for (Vec3f w : {Vec3f(0, 0, 1), FromAngles(20, 0), FromAngles(60, 100), FromAngles(10, 200)}) {
        Vec3d v = sky.xyY(w);
        Spectrum s = sky.RadianceSpectrum(w);
        double y = 0;
        for (int i = 0; i < Spectrum::kNumSamples; ++i) y += double(CieY().sample(i)) * s.sample(i);
        EXPECT_NEAR(683.002 * y, v.z, 1e-3 * v.z);
        Chromaticity xy = XYZToChromaticity(SpectrumToXYZ(s));
        // The CIE daylight basis reproduces chromaticities near the daylight locus to ~0.005.
        EXPECT_NEAR(xy.x, v.x, 0.006);
        EXPECT_NEAR(xy.y, v.y, 0.006);
        // The per-path evaluation agrees with the 1 nm spectrum.
        SampledWavelengths lambda = SampledWavelengths::SampleUniform(0.37f);
        SampledSpectrum r = sky.Radiance(w, lambda);
        for (int i = 0; i < kNumWavelengths; ++i)
            EXPECT_NEAR(r[i], s.Evaluate(lambda.lambda_nm(i)), 1e-3f * s.MaxValue());
    }
}

}  // namespace
}  // namespace nave
