#pragma once
// A participating medium (render's [medium] table): air with haze or dust, of spectral absorption
// and scattering coefficients at density 1 times a density over space (bricks/density_field.h:
// constant in a box, or an OpenVDB grid, whole or cut into the bricks), and a Henyey-Greenstein
// phase function. Light crossing it keeps exp(-σt ∫ density ds) of itself, σt = σa + σs
// (Beer-Lambert law: Bouguer 1729, Lambert 1760, Beer 1852).

#include <memory>

#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/render/bricks/density_field.h"
#include "src/render/bricks/resident_brick.h"
#include "src/render/scene/media/henyey_greenstein.h"
#include "src/render/scene/media/medium_emission.h"

namespace nave::render {

class Medium {
  public:
    /// The medium of `density` with absorption `sigma_a` and scattering `sigma_s` at density 1
    /// (m^-1, non-negative) and phase function asymmetry `g` in (-1, 1). A null `density` is the
    /// grid stored in the bricks: each brick's piece comes with the brick (ResidentBrick::medium).
    /// `emission` (null: none) is what it emits where its density is (medium_emission.h).
    Medium(std::shared_ptr<const DensityField> density, const Spectrum& sigma_a,
           const Spectrum& sigma_s, float g,
           std::shared_ptr<const MediumEmission> emission = nullptr)
        : density_(std::move(density)),
          sigma_a_(sigma_a),
          sigma_s_(sigma_s),
          phase_(g),
          emission_(std::move(emission)) {}

    /// The density a ray meets while it is processed in `brick` (null: outside every brick, before
    /// it enters the first): the medium's own field, which holds everywhere, or the brick's piece
    /// of the stored grid, which holds inside its cell (null: none there). The density between
    /// two bricks' cells is 0 in a stored grid: preprocess gives every cell with voxels a brick.
    const DensityField* DensityIn(const ResidentBrick* brick) const {
        if (density_) return density_.get();
        return brick != nullptr ? brick->medium() : nullptr;
    }
    bool in_bricks() const { return density_ == nullptr; }
    const HenyeyGreenstein& phase() const { return phase_; }
    /// What it emits; null: nothing.
    const MediumEmission* emission() const { return emission_.get(); }
    /// σa, σs and σt at density 1.
    SampledSpectrum SigmaA(const SampledWavelengths& lambda) const {
        return sigma_a_.Sample(lambda);
    }
    SampledSpectrum SigmaS(const SampledWavelengths& lambda) const {
        return sigma_s_.Sample(lambda);
    }
    SampledSpectrum SigmaT(const SampledWavelengths& lambda) const {
        return sigma_a_.Sample(lambda) + sigma_s_.Sample(lambda);
    }
    /// The transmittance exp(-σt depth) across `depth` of the density's integral, at each
    /// wavelength.
    SampledSpectrum Transmittance(float depth, const SampledWavelengths& lambda) const;

  private:
    std::shared_ptr<const DensityField> density_;
    Spectrum sigma_a_, sigma_s_;
    HenyeyGreenstein phase_;
    std::shared_ptr<const MediumEmission> emission_;
};

}  // namespace nave::render
