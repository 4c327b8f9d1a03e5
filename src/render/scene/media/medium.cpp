#include "src/render/scene/media/medium.h"

#include <cmath>

namespace nave::render {

SampledSpectrum Medium::Transmittance(float depth, const SampledWavelengths& lambda) const {
    if (depth == 0) return SampledSpectrum(1.f);
    const SampledSpectrum sigma_t = SigmaT(lambda);
    SampledSpectrum t;
    for (int i = 0; i < kNumWavelengths; ++i) t[i] = std::exp(-sigma_t[i] * depth);
    return t;
}

}  // namespace nave::render
