#pragma once
// A participating medium (render's [medium] table): air with haze or dust, of spectral absorption
// and scattering coefficients at density 1 times a density over space (density_field.h: constant in
// a box, or an OpenVDB grid), and a Henyey-Greenstein phase function. Light crossing it keeps
// exp(-σt ∫ density ds) of itself, σt = σa + σs (Beer-Lambert law: Bouguer 1729, Lambert 1760,
// Beer 1852).

#include <memory>

#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/render/scene/media/density_field.h"
#include "src/render/scene/media/henyey_greenstein.h"

namespace nave::render {

class Medium {
  public:
    /// The medium of `density` (not null) with absorption `sigma_a` and scattering `sigma_s` at
    /// density 1 (m^-1, non-negative) and phase function asymmetry `g` in (-1, 1).
    Medium(std::shared_ptr<const DensityField> density, const Spectrum& sigma_a,
           const Spectrum& sigma_s, float g)
        : density_(std::move(density)), sigma_a_(sigma_a), sigma_s_(sigma_s), phase_(g) {}

    const DensityField& density() const { return *density_; }
    const HenyeyGreenstein& phase() const { return phase_; }
    /// σs and σt at density 1.
    SampledSpectrum SigmaS(const SampledWavelengths& lambda) const {
        return sigma_s_.Sample(lambda);
    }
    SampledSpectrum SigmaT(const SampledWavelengths& lambda) const {
        return sigma_a_.Sample(lambda) + sigma_s_.Sample(lambda);
    }
    /// The transmittance exp(-σt ∫ density) along o + t d, t in [0, t_max], at each wavelength.
    SampledSpectrum Transmittance(const Vec3f& o, const Vec3f& d, float t_max,
                                  const SampledWavelengths& lambda) const;

  private:
    std::shared_ptr<const DensityField> density_;
    Spectrum sigma_a_, sigma_s_;
    HenyeyGreenstein phase_;
};

}  // namespace nave::render
