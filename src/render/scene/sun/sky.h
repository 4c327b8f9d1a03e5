#pragma once
// The clear sky's spectral radiance by the analytic model of Preetham, Shirley & Smits, "A
// practical analytic model for daylight", SIGGRAPH 1999: Perez et al. (1993) luminance/chromaticity
// distributions fitted against turbidity, then a spectrum from the chromaticity through the CIE
// daylight basis. Known limits (Zotti et al. 2007; Hosek & Wilkie 2012): fair for turbidity 2-6 and
// a sun well above the horizon; too bright near the horizon at low sun. Good enough for a first
// interior daylight.

#include "src/core/spectrum.h"
#include "src/core/vecmath.h"

namespace nave {

class PreethamSky {
  public:
    /// `sun_direction`: unit vector to the sun, world frame (+Z up). `turbidity` in [1.7, 10].
    PreethamSky(const Vec3f& sun_direction, float turbidity);

    /// Chromaticity x, y and luminance Y (cd/m²) of the sky in direction `w` (world, +Z up); zero
    /// below the horizon.
    Vec3d xyY(const Vec3f& w) const;
    /// Spectral radiance (W m⁻² sr⁻¹ nm⁻¹) in direction `w` at the path's wavelengths: the CIE
    /// daylight spectrum of the sky's chromaticity, scaled to its luminance (683 lm/W · Σ L ȳ = Y).
    SampledSpectrum Radiance(const Vec3f& w, const SampledWavelengths& lambda) const;
    /// The same as a 1 nm spectrum (for tools and tests).
    Spectrum RadianceSpectrum(const Vec3f& w) const;

    /// Zenith luminance (cd/m²) and chromaticity (Preetham et al. 1999 Appendix A.2).
    double zenith_luminance() const { return zenith_[2]; }
    double zenith_x() const { return zenith_[0]; }
    double zenith_y() const { return zenith_[1]; }

  private:
    Vec3f sun_;
    double theta_sun_ = 0;
    // Perez coefficients A..E for x, y, Y.
    double perez_[3][5] = {};
    double zenith_[3] = {};
    double Perez(int channel, double theta, double gamma) const;
};

}  // namespace nave
