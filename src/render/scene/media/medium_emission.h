#pragma once
// What a participating medium emits (a flame, glowing gas, a luminous fog): a radiance Le at each
// point, whose source term in the radiative transfer equation is σa ρ Le (Chandrasekhar 1960,
// "Radiative Transfer", §1.4; pbrt-v4 §11.1.3): a medium in thermal equilibrium absorbs and emits
// alike (Kirchhoff's law), so a medium thick enough glows at Le, and at Le = B(λ, T), Planck's
// black body radiance at its temperature, a hot gas glows as physics says it does.

#include <memory>

#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/volumes/vdb_plugin.h"

namespace nave::render {

class MediumEmission {
  public:
    /// Radiance `le` (W m^-2 sr^-1 nm^-1) wherever the medium is.
    static MediumEmission Uniform(const Spectrum& le);
    /// `le` times the value of `grid` at each point (0 outside its active voxels).
    static MediumEmission Scaled(const Spectrum& le,
                                 std::shared_ptr<const volumes::ScalarGrid> grid);
    /// Planck's radiance at the temperature `grid` holds, in kelvin, times `temperature_scale`,
    /// all times `scale`.
    static MediumEmission Blackbody(std::shared_ptr<const volumes::ScalarGrid> grid,
                                    float temperature_scale, float scale);

    /// Le at point `p`, at each wavelength of `lambda`.
    SampledSpectrum Radiance(const Vec3f& p, const SampledWavelengths& lambda) const;
    /// The grid the emission follows (null: uniform): it emits only in that grid's active voxels.
    const volumes::ScalarGrid* grid() const { return grid_.get(); }

  private:
    MediumEmission() = default;
    Spectrum le_;  ///< Uniform, Scaled
    std::shared_ptr<const volumes::ScalarGrid> grid_;
    bool blackbody_ = false;
    float temperature_scale_ = 1, scale_ = 1;
};

}  // namespace nave::render
