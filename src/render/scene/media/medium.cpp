#include "src/render/scene/media/medium.h"

#include <cmath>

namespace nave::render {

SampledSpectrum Medium::Transmittance(const Vec3f& o, const Vec3f& d, float t_max,
                                      const SampledWavelengths& lambda) const {
    const float depth = density_->Integral(o, d, t_max);
    if (depth == 0) return SampledSpectrum(1.f);
    const SampledSpectrum sigma_t = SigmaT(lambda);
    SampledSpectrum t;
    for (int i = 0; i < kNumWavelengths; ++i) t[i] = std::exp(-sigma_t[i] * depth);
    return t;
}

}  // namespace nave::render
