#include "src/render/scene/sun/sun.h"

#include <cmath>
#include <numbers>

#include "src/core/check.h"
#include "src/core/color.h"
#include "src/core/spectrum_data.h"
#include "src/render/scene/materials/frame.h"

namespace nave {

namespace {
constexpr double kPiD = std::numbers::pi;
double Rad(double deg) { return deg * kPiD / 180.0; }
}  // namespace

double RelativeAirMassKastenYoung(double zenith_deg) {
    NAVE_CHECK(zenith_deg >= 0 && zenith_deg < 96.07995) << zenith_deg;
    // Kasten & Young (1989) eq. (3), a = 0.50572, b = 6.07995°, c = 1.6364.
    return 1.0 / (std::cos(Rad(zenith_deg)) + 0.50572 * std::pow(96.07995 - zenith_deg, -1.6364));
}

double RayleighOpticalDepth(double lambda_nm, double pressure_hpa) {
    // Bodhaine et al. (1999) eq. (30), λ in µm.
    double l = lambda_nm / 1000.0;
    double l2 = l * l;
    double tau = 0.0021520 * (1.0455996 - 341.29061 / l2 - 0.90230850 * l2) /
                 (1.0 + 0.0027059889 / l2 - 85.968563 * l2);
    return tau * pressure_hpa / 1013.25;
}

double AngstromBetaFromTurbidity(double turbidity) {
    return std::max(0.0, 0.04608365822050 * turbidity - 0.04586025928522);
}

const Spectrum& ExtraterrestrialSolarSpectrum() {
    static const Spectrum s = EmbeddedSpectraTable("solar_astm_e490_am0.csv").ToSpectrum(0);
    return s;
}

double IlluminanceLux(const Spectrum& irradiance) {
    // Luminous efficacy of radiation at 540 THz: Km = 683 lm/W (SI definition of the candela); the
    // photopic curve V(λ) is the CIE 1931 ȳ.
    const Spectrum& y = CieY();
    double sum = 0;
    for (int i = 0; i < Spectrum::kNumSamples; ++i)
        sum += double(y.sample(i)) * irradiance.sample(i);
    return 683.002 * sum;
}

double Sun::SolidAngle() const { return ConeSolidAngle(angular_radius_rad); }

Vec3f Sun::SampleDirection(Point2f u) const {
    Vec3f local = SampleUniformNarrowCone(u, angular_radius_rad);
    return Normalize(Frame::FromZ(direction).FromLocal(local));
}

float Sun::Pdf(const Vec3f& w) const {
    if (!InNarrowCone(w, direction, angular_radius_rad)) return 0.f;
    return float(1.0 / SolidAngle());
}

StatusOr<Sun> ComputeSun(const SunInput& in) {
    const Atmosphere& atm = in.atmosphere;
    if (!(atm.turbidity >= 1.0 && atm.turbidity <= 64.0))
        return InvalidArgumentError("turbidity {} out of range [1, 64]", atm.turbidity);
    if (!(atm.ozone_atm_cm >= 0 && atm.ozone_atm_cm <= 1.0))
        return InvalidArgumentError("ozone column {} atm-cm out of range [0, 1]", atm.ozone_atm_cm);
    if (!(atm.water_vapour_cm >= 0 && atm.water_vapour_cm <= 10.0))
        return InvalidArgumentError("precipitable water {} cm out of range [0, 10]",
                                    atm.water_vapour_cm);
    SpaInput spa;
    spa.time = in.time;
    spa.delta_t_s = in.delta_t_s;
    spa.latitude_deg = in.latitude_deg;
    spa.longitude_deg = in.longitude_deg;
    spa.elevation_m = in.elevation_m;
    spa.pressure_hpa = atm.pressure_hpa;
    spa.temperature_c = atm.temperature_c;
    NAVE_ASSIGN_OR_RETURN(SpaResult pos, ComputeSolarPosition(spa));

    Sun sun;
    sun.position = pos;
    // Azimuth from north, clockwise; world +X east, +Y north, +Z up.
    double el = Rad(pos.elevation_deg), az = Rad(pos.azimuth_deg);
    sun.direction = Normalize(Vec3f(float(std::cos(el) * std::sin(az)),
                                    float(std::cos(el) * std::cos(az)), float(std::sin(el))));
    sun.distance_au = pos.r_au;
    // Apparent radius: IAU 2015 nominal solar radius 695700 km; 1 AU = 149597870.7 km (IAU 2012).
    sun.angular_radius_rad = std::asin(695700.0 / (pos.r_au * 149597870.7));

    // Earth-Sun distance correction of the date: irradiance falls as 1/r².
    double inv_r2 = 1.0 / (pos.r_au * pos.r_au);
    sun.extraterrestrial_irradiance = ExtraterrestrialSolarSpectrum() * float(inv_r2);

    if (sun.AboveHorizon() && pos.zenith_deg < 90.0) {
        sun.air_mass = RelativeAirMassKastenYoung(pos.zenith_deg);
        sun.direct_normal_irradiance = DirectNormalIrradiance(pos.zenith_deg, atm, pos.r_au);
    }
    sun.radiance = sun.direct_normal_irradiance * float(1.0 / sun.SolidAngle());
    return sun;
}

Spectrum DirectNormalIrradiance(double zenith_deg, const Atmosphere& atm, double distance_au) {
    const double m = RelativeAirMassKastenYoung(zenith_deg);
    // The pressure-corrected air mass, for the uniformly mixed gases (Leckner 1978). Rayleigh
    // scattering is already scaled by p / p0 in its optical depth: it takes m.
    const double m_p = m * atm.pressure_hpa / 1013.25;
    // Ozone sits at ~22 km: its air mass differs from the total near the horizon (Iqbal 1983
    // eq. 5.3.3 after Robinson 1966: m_oz = (1 + h/R) / sqrt(cos²z + 2h/R), h/R = 22/6370).
    double cz = std::cos(Rad(zenith_deg));
    double m_oz = (1.0 + 22.0 / 6370.0) / std::sqrt(cz * cz + 2.0 * 22.0 / 6370.0);
    double beta = AngstromBetaFromTurbidity(atm.turbidity);
    const SpectraTable& oz = EmbeddedSpectraTable("atmosphere_ozone_k.csv");
    const SpectraTable& gas = EmbeddedSpectraTable("atmosphere_gases_k.csv");
    static const Spectrum k_o = oz.ToSpectrum(0);
    static const Spectrum k_g = gas.ToSpectrum(0);
    static const Spectrum k_w = gas.ToSpectrum(1);
    const Spectrum e0 = ExtraterrestrialSolarSpectrum() * float(1 / (distance_au * distance_au));
    double w = atm.water_vapour_cm;
    return Spectrum::FromFunction([&](double l) {
        int i = int(l - kLambdaMinNm);
        double tau_r = RayleighOpticalDepth(l, atm.pressure_hpa);
        double tau_a = beta * std::pow(l / 1000.0, -atm.angstrom_alpha);
        double tau_o = k_o.sample(i) * atm.ozone_atm_cm;
        // Leckner (1978) eqs. (2.36)-(2.37) for the O2 A band and water vapour (Iqbal 1983
        // eq. 6.12.7-8).
        double kg = k_g.sample(i), kw = k_w.sample(i);
        double t_g = std::exp(-1.41 * kg * m_p / std::pow(1.0 + 118.93 * kg * m_p, 0.45));
        double t_w = std::exp(-0.2385 * kw * w * m / std::pow(1.0 + 20.07 * kw * w * m, 0.45));
        return e0.sample(i) * std::exp(-m * (tau_r + tau_a) - m_oz * tau_o) * t_g * t_w;
    });
}

}  // namespace nave
