#include "src/render/scene/media/medium_emission.h"

namespace nave::render {

MediumEmission MediumEmission::Uniform(const Spectrum& le) {
    MediumEmission e;
    e.le_ = le;
    return e;
}

MediumEmission MediumEmission::Scaled(const Spectrum& le,
                                      std::shared_ptr<const volumes::ScalarGrid> grid) {
    MediumEmission e;
    e.le_ = le;
    e.grid_ = std::move(grid);
    return e;
}

MediumEmission MediumEmission::Blackbody(std::shared_ptr<const volumes::ScalarGrid> grid,
                                         float temperature_scale, float scale) {
    MediumEmission e;
    e.grid_ = std::move(grid);
    e.blackbody_ = true;
    e.temperature_scale_ = temperature_scale;
    e.scale_ = scale;
    return e;
}

SampledSpectrum MediumEmission::Radiance(const Vec3f& p, const SampledWavelengths& lambda) const {
    if (!grid_) return le_.Sample(lambda);
    const float value = grid_->Value(p);
    if (!(value > 0)) return SampledSpectrum(0.f);
    if (!blackbody_) return le_.Sample(lambda) * value;
    const double kelvin = double(value) * double(temperature_scale_);
    SampledSpectrum le;
    // Planck's law, absolute (W m^-2 sr^-1 nm^-1): core/spectrum.h PlanckRadiance.
    for (int i = 0; i < kNumWavelengths; ++i)
        le[i] = float(PlanckRadiance(lambda[i], kelvin) * double(scale_));
    return le;
}

}  // namespace nave::render
