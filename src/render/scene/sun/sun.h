#pragma once
// The sun as a light source: its position (SPA, spa.h), its direct spectral irradiance at the
// ground through a clear atmosphere, and its disc of true angular size for sampling.
//
// Direct normal spectral irradiance (Iqbal 1983, ch. 6; the same transmittances as Preetham,
// Shirley & Smits 1999, Appendix):
//   E(λ) = E0(λ) / r² · exp(-m τ_R(λ, p) - m_oz τ_oz(λ) - m τ_a(λ)) · T_g(λ, m_p) · T_w(λ)
// E0: ASTM E-490-00a extraterrestrial spectrum at 1 AU; r: Earth-Sun distance (AU) of the date from
// the SPA; m: relative air mass (Kasten & Young 1989); τ_R: Rayleigh optical depth at the station
// pressure p (Bodhaine et al. 1999 eq. 30 times p/1013.25, so with m, not with m_p = m p/1013.25,
// which the mixed gases' T_g takes); τ_oz = k_o(λ) · ozone column (Iqbal/Vigroux table); τ_a = β
// λ^-α (Ångström 1929, β from the turbidity as in Preetham et al. 1999); T_g, T_w: O2 and
// water-vapour bands (Leckner 1978).

#include "src/core/sampling.h"
#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/render/scene/sun/spa.h"

namespace nave {

/// Relative optical air mass for an apparent (refracted) zenith angle, Kasten & Young (1989),
/// Applied Optics 28(22) 4735-4738: m = 1 / (cos z + 0.50572 (96.07995° - z)^-1.6364). 1 at the
/// zenith, 5.586 at 80°, ~38 at the horizon. CHECKs z in [0, 96°).
double RelativeAirMassKastenYoung(double zenith_deg);
/// Rayleigh optical depth of the whole atmosphere at `lambda_nm` for a station pressure (Bodhaine,
/// Wood, Dutton & Slusser 1999, J. Atmos. Oceanic Technol. 16, 1854, eq. 30: sea level, 45° N, 360
/// ppm CO2, scaled by p / 1013.25 hPa). 0.0971 at 550 nm at sea level.
double RayleighOpticalDepth(double lambda_nm, double pressure_hpa = 1013.25);
/// Ångström coefficient β of aerosol optical depth τ_a = β λ[µm]^-α for a Preetham turbidity T
/// (Preetham, Shirley & Smits 1999, Appendix A.2: β = 0.04608 T - 0.04586). T = 2 is very clear, 3
/// clear, 6+ hazy.
double AngstromBetaFromTurbidity(double turbidity);

/// The clear-sky state of the atmosphere.
struct Atmosphere {
    double pressure_hpa = 1013.25;  ///< station pressure
    double temperature_c = 15.0;    ///< for refraction
    double turbidity = 3.0;         ///< Preetham turbidity (aerosols), >= 1.7
    double angstrom_alpha = 1.3;    ///< Ångström exponent (1.3: Ångström's continental mean)
    double ozone_atm_cm = 0.30;     ///< ozone column, atm-cm (0.30 = 300 Dobson units)
    double water_vapour_cm = 1.4;   ///< precipitable water, cm
};

/// Where and when.
struct SunInput {
    CivilTime time;
    double latitude_deg = 0, longitude_deg = 0, elevation_m = 0;
    double delta_t_s = 69.0;
    Atmosphere atmosphere;
};

/// The sun for one place and time. A value type; build once per render.
struct Sun {
    SpaResult position;
    /// Unit vector towards the sun's centre in nave's world frame (+X east, +Y north, +Z up).
    Vec3f direction;
    /// Relative air mass (Kasten & Young) of the apparent zenith angle; 0 when the sun is below the
    /// horizon.
    double air_mass = 0;
    /// Earth-Sun distance of the date (AU) and the apparent angular radius of the disc (radians).
    double distance_au = 1;
    double angular_radius_rad = 0;
    /// Direct normal spectral irradiance at the ground, W m⁻² nm⁻¹ (zero when the sun has set).
    Spectrum direct_normal_irradiance;
    /// Spectral radiance of the disc, W m⁻² sr⁻¹ nm⁻¹: irradiance over the disc's solid angle (a
    /// uniform disc; limb darkening neglected).
    Spectrum radiance;
    /// Same direct irradiance at the top of the atmosphere (for reference).
    Spectrum extraterrestrial_irradiance;

    bool AboveHorizon() const { return position.elevation_deg > -0.8333; }
    /// Solid angle of the disc (sr).
    double SolidAngle() const;
    /// A direction uniformly distributed over the disc (cone around `direction`), world frame.
    Vec3f SampleDirection(Point2f u) const;
    /// The solid-angle pdf of SampleDirection for `w` (0 outside the disc).
    float Pdf(const Vec3f& w) const;
};

/// Computes position (SPA with refraction) and spectrum. InvalidArgument for out-of-range inputs.
StatusOr<Sun> ComputeSun(const SunInput& in);
/// The direct normal spectral irradiance (W m⁻² nm⁻¹) through `atm` of a sun at apparent zenith
/// angle `zenith_deg` (in [0, 90)) and `distance_au` (the formula at the top of this file).
/// Expects an atmosphere ComputeSun accepts.
Spectrum DirectNormalIrradiance(double zenith_deg, const Atmosphere& atm, double distance_au);

/// Direct normal illuminance (lux) of a spectral irradiance in W m⁻² nm⁻¹: 683.002 lm/W · Σ E ȳ
/// over 1 nm (Km = 683 lm/W from the SI definition of the candela; V(λ) = CIE 1931 ȳ).
double IlluminanceLux(const Spectrum& irradiance_w_m2_nm);

/// The extraterrestrial solar spectrum at 1 AU (ASTM E-490-00a), W m⁻² nm⁻¹, 360-830 nm.
const Spectrum& ExtraterrestrialSolarSpectrum();

}  // namespace nave
