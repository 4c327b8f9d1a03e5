// Solar position and the sun's spectrum against published values; each test names its source.

#include "src/render/scene/sun/sun.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "src/core/color.h"
#include "src/core/sampling.h"
#include "src/render/scene/sun/spa.h"

namespace nave {
namespace {

// The worked example of Reda & Andreas (2004), Table A5.1 (NREL/TP-560-34302 rev. 2008, Appendix
// A.5): 2003-10-17 12:30:30 local time, zone -7, ΔT = 67 s, 39.742476° N, 105.1786° W, 1830.14 m,
// 820 mbar, 11 °C. Tolerance on the final angles 0.001° as the brief asks; intermediates to the
// table's digits.
TEST(SpaTest, ReferenceExample) {
    SpaInput in;
    in.time = {2003, 10, 17, 12, 30, 30.0, -7.0};
    in.delta_t_s = 67.0;
    in.latitude_deg = 39.742476;
    in.longitude_deg = -105.1786;
    in.elevation_m = 1830.14;
    in.pressure_hpa = 820.0;
    in.temperature_c = 11.0;
    StatusOr<SpaResult> r = ComputeSolarPosition(in);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_NEAR(r->jd, 2452930.312847, 1e-6);
    EXPECT_NEAR(r->l_deg, 24.0182616917, 1e-6);
    EXPECT_NEAR(r->b_deg, -0.0001011219, 1e-9);
    EXPECT_NEAR(r->r_au, 0.9965422974, 1e-9);
    EXPECT_NEAR(r->delta_psi_deg, -0.00399840, 1e-8);
    EXPECT_NEAR(r->delta_epsilon_deg, 0.00166657, 1e-8);
    EXPECT_NEAR(r->epsilon_deg, 23.440465, 1e-6);
    EXPECT_NEAR(r->lambda_deg, 204.0085519281, 1e-6);
    EXPECT_NEAR(r->alpha_deg, 202.22741, 1e-5);
    EXPECT_NEAR(r->delta_deg, -9.31434, 1e-5);
    EXPECT_NEAR(r->h_deg, 11.105900, 1e-5);
    EXPECT_NEAR(r->alpha_prime_deg, 202.22704, 1e-5);
    EXPECT_NEAR(r->delta_prime_deg, -9.316179, 1e-6);
    EXPECT_NEAR(r->h_prime_deg, 11.10629, 3e-5);
    EXPECT_NEAR(r->zenith_deg, 50.11162, 1e-3);
    EXPECT_NEAR(r->azimuth_deg, 194.34024, 1e-3);
}

// Meeus, Astronomical Algorithms (2nd ed.), ch. 7 examples: Julian Days across the calendar change.
TEST(SpaTest, JulianDayGregorianAndJulianCalendars) {
    EXPECT_DOUBLE_EQ(JulianDay(2000, 1, 1.5), 2451545.0);
    EXPECT_DOUBLE_EQ(JulianDay(1957, 10, 4.81), 2436116.31);
    EXPECT_DOUBLE_EQ(JulianDay(1582, 10, 15.0), 2299160.5);  // first Gregorian day
    EXPECT_DOUBLE_EQ(JulianDay(1582, 10, 4.0), 2299159.5);   // last Julian day, the day before
    EXPECT_DOUBLE_EQ(JulianDay(333, 1, 27.5), 1842713.0);    // Julian calendar
    EXPECT_DOUBLE_EQ(JulianDay(-1000, 7, 12.5), 1356001.0);
}

// Espenak & Meeus (2006) Table 2.1 (ΔT at the start of each century, from the same model) and the
// observed value of 2000 (63.8 s, IERS).
TEST(SpaTest, DeltaTEstimate) {
    EXPECT_NEAR(EstimateDeltaT(2000.0), 63.8, 0.2);
    EXPECT_NEAR(EstimateDeltaT(1900.0), -2.7, 0.5);
    EXPECT_NEAR(EstimateDeltaT(1800.0), 13.7, 0.5);
    EXPECT_NEAR(EstimateDeltaT(1700.0), 8.8, 0.5);
    EXPECT_NEAR(EstimateDeltaT(1600.0), 120.0, 2.0);
    EXPECT_NEAR(EstimateDeltaT(1500.0), 200.0, 10.0);
    EXPECT_NEAR(EstimateDeltaT(1000.0), 1570.0, 10.0);
    EXPECT_NEAR(EstimateDeltaT(0.0), 10580.0, 30.0);
    // Continuous across the period boundaries (within a few seconds).
    for (double y :
         {500.0, 1600.0, 1700.0, 1800.0, 1860.0, 1900.0, 1920.0, 1941.0, 1961.0, 1986.0, 2005.0})
        EXPECT_NEAR(EstimateDeltaT(y - 1e-6), EstimateDeltaT(y), 5.0) << y;
}

TEST(SpaTest, RejectsOutOfRangeInput) {
    SpaInput in;
    in.time = {2003, 10, 17, 12, 30, 30.0, -7.0};
    in.latitude_deg = 91;
    StatusOr<SpaResult> r = ComputeSolarPosition(in);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find("latitude 91"), std::string::npos) << r.status().message();
    in.latitude_deg = 0;
    in.time.year = 7000;
    EXPECT_FALSE(ComputeSolarPosition(in).ok());
}

TEST(Iso8601Test, ParsesZonesAndRefusesLocalTime) {
    StatusOr<CivilTime> t = ParseIso8601("2003-10-17T12:30:30-07:00");
    ASSERT_TRUE(t.ok()) << t.status().ToString();
    EXPECT_EQ(t->year, 2003);
    EXPECT_EQ(t->hour, 12);
    EXPECT_DOUBLE_EQ(t->second, 30.0);
    EXPECT_DOUBLE_EQ(t->utc_offset_hours, -7.0);
    EXPECT_DOUBLE_EQ(ParseIso8601("2024-06-21 12:00Z")->utc_offset_hours, 0.0);
    EXPECT_DOUBLE_EQ(ParseIso8601("2024-06-21T12:00:00.5+0530")->utc_offset_hours, 5.5);
    EXPECT_DOUBLE_EQ(ParseIso8601("1200-03-01T09:00+01")->utc_offset_hours, 1.0);
    StatusOr<CivilTime> no_zone = ParseIso8601("2003-10-17T12:30:30");
    ASSERT_FALSE(no_zone.ok());
    EXPECT_NE(no_zone.status().message().find("no time zone"), std::string::npos);
    EXPECT_FALSE(ParseIso8601("2003-02-30T12:00Z").ok());
    EXPECT_FALSE(ParseIso8601("1582-10-10T12:00Z").ok());
    EXPECT_FALSE(ParseIso8601("yesterday").ok());
    EXPECT_EQ(FormatIso8601(*t), "2003-10-17T12:30:30.000-07:00");
}

// Kasten & Young (1989) Table: m(80°) = 5.586, m(0°) = 1.000 (more precisely 0.99976).
TEST(AtmosphereTest, KastenYoungAirMass) {
    EXPECT_NEAR(RelativeAirMassKastenYoung(0.0), 1.000, 5e-4);
    EXPECT_NEAR(RelativeAirMassKastenYoung(80.0), 5.586, 1e-3);
    EXPECT_NEAR(RelativeAirMassKastenYoung(60.0), 1.9942, 1e-3);
    EXPECT_NEAR(RelativeAirMassKastenYoung(90.0), 37.92, 0.05);
}

// Bodhaine et al. (1999) Table 3 / eq. (30): Rayleigh optical depth at sea level ≈ 0.0971 at 550
// nm, 0.3639 (400 nm), 0.0364 (700 nm) for the standard atmosphere; proportional to pressure.
TEST(AtmosphereTest, BodhaineRayleighOpticalDepth) {
    EXPECT_NEAR(RayleighOpticalDepth(550.0), 0.097, 0.0015);
    EXPECT_NEAR(RayleighOpticalDepth(400.0), 0.3639, 0.004);
    EXPECT_NEAR(RayleighOpticalDepth(700.0), 0.0364, 0.0006);
    EXPECT_NEAR(RayleighOpticalDepth(550.0, 506.625) / RayleighOpticalDepth(550.0), 0.5, 1e-12);
}

// ASTM G173-03 direct normal (+ circumsolar) spectrum at air mass 1.5 (apparent zenith 48.236°),
// from SMARTS 2.9.2 with the U.S. Standard Atmosphere 1976 at 1013.25 hPa, 1.4164 cm of water,
// 0.3438 atm-cm of ozone and rural aerosol of optical depth 0.084 at 500 nm. The bands' ratio of
// direct to extraterrestrial irradiance (both columns of the standard's table, 1 nm steps, band
// means computed from it) is the atmosphere's transmittance, independent of the extraterrestrial
// spectrum each model starts from. nave's model, given the same atmosphere (β for the same 500-nm
// depth with α = 1.3), measures 0.993, 1.001, 1.008, 1.026, 1.021 and 1.012 of the standard's
// bands: within 1 % below 550 nm, where Rayleigh scattering and aerosols dominate, and up to 2.6 %
// too clear in 550-650 nm, where SMARTS also has absorbers nave's model leaves out (NO2, the O2-O2
// collision bands at 577 and 630 nm, weak water-vapour bands) and a newer ozone cross-section than
// the Vigroux table (about 0.017 of optical depth in all). So the bound is 1.5 % below 550 nm and
// 3 % above, not 2 % everywhere; an error in the Rayleigh depth of the size the audit found (τ_R
// off by 17 % at Denver's pressure) moves the 400-450 nm band by 6 %. At 1013.25 hPa that pressure
// error vanishes, so the test after this one checks the pressure scaling on its own.
TEST(SunTest, DirectBeamTransmittanceMatchesAstmG173) {
    struct Band {
        double from_nm, to_nm, g173_ratio;
    };
    const Band bands[] = {{400, 450, 0.5635}, {450, 500, 0.6622}, {500, 550, 0.7162},
                          {550, 600, 0.7322}, {600, 650, 0.7760}, {650, 686, 0.8270}};
    Atmosphere atm;
    atm.pressure_hpa = 1013.25;
    atm.water_vapour_cm = 1.4164;
    atm.ozone_atm_cm = 0.3438;
    atm.angstrom_alpha = 1.3;
    // Turbidity whose β gives τ_a(500 nm) = β 0.5^-1.3 = 0.084 (Preetham's β = 0.04608 T -
    // 0.04586).
    atm.turbidity = (0.084 * std::pow(0.5, 1.3) + 0.04586025928522) / 0.04608365822050;
    ASSERT_NEAR(AngstromBetaFromTurbidity(atm.turbidity) * std::pow(0.5, -1.3), 0.084, 1e-9);
    const Spectrum direct = DirectNormalIrradiance(48.236, atm, 1.0);
    const Spectrum& top = ExtraterrestrialSolarSpectrum();
    for (const Band& b : bands) {
        double d = 0, e = 0;
        for (double l = b.from_nm; l < b.to_nm; l += 1) {
            d += direct(float(l));
            e += top(float(l));
        }
        EXPECT_NEAR(d / e / b.g173_ratio, 1.0, b.to_nm <= 550 ? 0.015 : 0.03)
            << b.from_nm << "-" << b.to_nm << " nm";
    }
}

// Rayleigh scattering removes exp(-m τ_R(λ) p/p0) of the beam (Bodhaine et al. 1999 eq. 30, depth
// proportional to the station pressure; Beer-Lambert with the relative air mass m). Between two
// pressures at a wavelength clear of gas bands, the direct beam's ratio is that alone: at 400 nm,
// zenith 50°, 820 against 1013.25 hPa, exp(m τ_R0 (1 - 820/1013.25)) = 1.114, where applying the
// pressure twice (to τ_R and to m) gave 1.221.
TEST(SunTest, RayleighDepthFollowsPressureOnce) {
    Atmosphere sea, denver;
    denver.pressure_hpa = 820;
    const double zenith = 50, m = RelativeAirMassKastenYoung(zenith);
    const double ratio = DirectNormalIrradiance(zenith, denver, 1.0)(400.f) /
                         DirectNormalIrradiance(zenith, sea, 1.0)(400.f);
    const double expected = std::exp(m * RayleighOpticalDepth(400.0) * (1 - 820 / 1013.25));
    EXPECT_NEAR(ratio, expected, 1e-4 * expected);
}

// The disc is 1 - cos θ ≈ 1.1e-5 wide: in float its cosine takes ~180 values. The solid angle and
// the samples must keep their precision (Ω = 2π(1 - cos θ) = 4π sin²(θ/2)).
TEST(SunTest, TheNarrowDiscKeepsItsPrecision) {
    const double radius = 0.2666 * M_PI / 180;
    EXPECT_NEAR(ConeSolidAngle(radius), 4 * M_PI * std::pow(std::sin(radius / 2), 2), 1e-15);
    EXPECT_NEAR(ConeSolidAngle(radius) / 6.80180e-5, 1.0, 1e-5);
    // Samples: 1 - cos θ uniform on [0, 1 - cos θmax] (uniform over the disc); many distinct
    // angles.
    const Vec3f axis(0, 0, 1);
    const double max_one_minus_cos = OneMinusCos(radius);
    int inner = 0;
    std::vector<float> sines;
    constexpr int kN = 20000;
    for (int i = 0; i < kN; ++i) {
        const Point2f u((float(i) + 0.5f) / kN, std::fmod(float(i) * 0.618034f, 1.f));
        const Vec3f w = SampleUniformNarrowCone(u, radius);
        ASSERT_TRUE(InNarrowCone(w, axis, radius * (1 + 1e-6))) << i;
        const double sin2 = double(w.x) * w.x + double(w.y) * w.y;
        if (sin2 / 2 < 0.5 * max_one_minus_cos) ++inner;  // 1 - cos θ ≈ sin²θ / 2 here
        sines.push_back(float(std::sqrt(sin2)));
    }
    EXPECT_NEAR(double(inner) / kN, 0.5, 0.005);
    std::sort(sines.begin(), sines.end());
    EXPECT_GT(std::unique(sines.begin(), sines.end()) - sines.begin(), 10000);
    EXPECT_FALSE(InNarrowCone(
        Vec3f(std::sin(float(radius) * 1.01f), 0, std::cos(float(radius) * 1.01f)), axis, radius));
    EXPECT_TRUE(InNarrowCone(
        Vec3f(std::sin(float(radius) * 0.99f), 0, std::cos(float(radius) * 0.99f)), axis, radius));
}

SunInput DenverNoon() {
    SunInput in;
    in.time = {2003, 10, 17, 12, 30, 30.0, -7.0};
    in.delta_t_s = 67.0;
    in.latitude_deg = 39.742476;
    in.longitude_deg = -105.1786;
    in.elevation_m = 1830.14;
    in.atmosphere.pressure_hpa = 820.0;
    in.atmosphere.temperature_c = 11.0;
    return in;
}

TEST(SunTest, SpectrumAndDisc) {
    StatusOr<Sun> sun = ComputeSun(DenverNoon());
    ASSERT_TRUE(sun.ok()) << sun.status().ToString();
    // Direction: azimuth 194° (a little west of south), elevation ~39.9°.
    EXPECT_LT(sun->direction.y, 0.f);
    EXPECT_LT(sun->direction.x, 0.f);
    EXPECT_NEAR(std::asin(sun->direction.z) * 180 / M_PI, 90.0 - 50.11162, 1e-3);
    // Angular radius: 959.63" / r (IAU) -> 0.2676° at r = 0.99654 AU.
    EXPECT_NEAR(sun->angular_radius_rad * 180 / M_PI, 0.2675, 5e-4);
    // The atmosphere only removes light, more in the blue than in the red.
    for (float l : {400.f, 500.f, 600.f, 700.f})
        EXPECT_LT(sun->direct_normal_irradiance(l), sun->extraterrestrial_irradiance(l)) << l;
    double t450 = sun->direct_normal_irradiance(450.f) / sun->extraterrestrial_irradiance(450.f);
    double t700 = sun->direct_normal_irradiance(700.f) / sun->extraterrestrial_irradiance(700.f);
    EXPECT_LT(t450, t700);
    // Clear-sky direct normal illuminance with the sun 40° high: 75-110 klx (CIE 110-1994 / Darula
    // & Kittler 2002 clear-sky parallel-beam illuminance; the extraterrestrial value is ~133 klx).
    double lux = IlluminanceLux(sun->direct_normal_irradiance);
    EXPECT_GT(lux, 75000.0);
    EXPECT_LT(lux, 110000.0);
    double lux0 = IlluminanceLux(sun->extraterrestrial_irradiance);
    EXPECT_NEAR(lux0 * sun->distance_au * sun->distance_au, 133000.0, 3000.0);
}

// Earth-Sun distance: perihelion in early January (0.9833 AU), aphelion in early July (1.0167 AU);
// irradiance scales as 1/r² (Astronomical Almanac).
TEST(SunTest, EarthSunDistanceOfTheDate) {
    SunInput jan = DenverNoon();
    jan.time = {2024, 1, 3, 12, 0, 0, 0};
    SunInput jul = DenverNoon();
    jul.time = {2024, 7, 5, 12, 0, 0, 0};
    StatusOr<Sun> a = ComputeSun(jan), b = ComputeSun(jul);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_NEAR(a->distance_au, 0.98331, 2e-4);
    EXPECT_NEAR(b->distance_au, 1.01672, 2e-4);
    EXPECT_NEAR(a->extraterrestrial_irradiance(550.f) / b->extraterrestrial_irradiance(550.f),
                std::pow(b->distance_au / a->distance_au, 2), 1e-5);
}

TEST(SunTest, NightHasNoDirectLight) {
    SunInput in = DenverNoon();
    in.time = {2003, 10, 17, 0, 30, 0, -7.0};
    StatusOr<Sun> sun = ComputeSun(in);
    ASSERT_TRUE(sun.ok());
    EXPECT_FALSE(sun->AboveHorizon());
    EXPECT_EQ(sun->direct_normal_irradiance.MaxValue(), 0.f);
    in.atmosphere.turbidity = 0.1;
    EXPECT_FALSE(ComputeSun(in).ok());
}

TEST(SunTest, DiscSamplingStaysInTheCone) {
    StatusOr<Sun> sun = ComputeSun(DenverNoon());
    ASSERT_TRUE(sun.ok());
    for (int i = 0; i < 1000; ++i) {
        Point2f u((i + 0.5f) / 1000.f, std::fmod(i * 0.618034f, 1.f));
        Vec3f w = sun->SampleDirection(u);
        EXPECT_NEAR(Length(w), 1.f, 1e-5f);
        EXPECT_TRUE(InNarrowCone(w, sun->direction, sun->angular_radius_rad * 1.001)) << i;
    }
    EXPECT_NEAR(sun->Pdf(sun->direction) * sun->SolidAngle(), 1.0, 1e-3);
    EXPECT_EQ(sun->Pdf(Vec3f(0, 0, -1)), 0.f);
}

}  // namespace
}  // namespace nave
