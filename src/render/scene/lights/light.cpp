#include "src/render/scene/lights/light.h"

#include "src/core/check.h"

namespace nave::render {

float MeanVisible(const Spectrum& s) {
    double sum = 0;
    for (int l = 400; l <= 700; l += 10) sum += s.Evaluate(float(l));
    return float(sum / 31);
}

PhotonSample Light::SamplePhoton(const PhotonRandoms&, const SampledWavelengths&) const {
    NAVE_CHECK(false) << "a light far away has no photons of its own: PhotonEmitters starts them";
    return {};
}

}  // namespace nave::render
