#pragma once
// A homogeneous participating medium filling an axis-aligned box (render's [medium] table): air
// with haze or dust, of spectral absorption and scattering coefficients and a Henyey-Greenstein
// phase function. Light crossing a length ℓ of it keeps exp(-σt ℓ) of itself, σt = σa + σs
// (Beer-Lambert law: Bouguer 1729, Lambert 1760, Beer 1852).

#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/render/scene/media/henyey_greenstein.h"

namespace nave::render {

class HomogeneousMedium {
  public:
    /// The medium in `box` (model units, metres) with absorption `sigma_a` and scattering
    /// `sigma_s` (m^-1, non-negative) and phase function asymmetry `g` in (-1, 1).
    HomogeneousMedium(const Bounds3f& box, const Spectrum& sigma_a, const Spectrum& sigma_s,
                      float g)
        : box_(box), sigma_a_(sigma_a), sigma_s_(sigma_s), phase_(g) {}

    const Bounds3f& box() const { return box_; }
    const HenyeyGreenstein& phase() const { return phase_; }
    SampledSpectrum SigmaS(const SampledWavelengths& lambda) const {
        return sigma_s_.Sample(lambda);
    }
    SampledSpectrum SigmaT(const SampledWavelengths& lambda) const {
        return sigma_a_.Sample(lambda) + sigma_s_.Sample(lambda);
    }
    /// The part [*t0, *t1] of the ray o + t d (d unit), t in [0, t_max], inside the box; false
    /// when the ray does not cross it there.
    bool Overlap(const Vec3f& o, const Vec3f& d, float t_max, float* t0, float* t1) const;
    /// The length of the ray o + t d, t in [0, t_max], inside the box.
    float LengthInside(const Vec3f& o, const Vec3f& d, float t_max) const {
        float t0, t1;
        return Overlap(o, d, t_max, &t0, &t1) ? t1 - t0 : 0.f;
    }
    /// The transmittance exp(-σt ℓ) along o + t d, t in [0, t_max], at each wavelength.
    SampledSpectrum Transmittance(const Vec3f& o, const Vec3f& d, float t_max,
                                  const SampledWavelengths& lambda) const;

  private:
    Bounds3f box_;
    Spectrum sigma_a_, sigma_s_;
    HenyeyGreenstein phase_;
};

}  // namespace nave::render
