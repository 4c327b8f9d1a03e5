#include "src/render/scene/lights/directional_light.h"

namespace nave::render {

std::optional<LightSample> DirectionalLight::SampleLi(const Vec3f&, Point2f,
                                                      const SampledWavelengths& lambda) const {
    // The paper's eq. 3: L_r = F_r(w_s, w_o) L_s (n . w_s), with L_s the irradiance at normal
    // incidence.
    LightSample s;
    s.wi = to_light();
    s.weight = irradiance_.Sample(lambda);
    return s;
}

SampledSpectrum DirectionalLight::PhotonPower(const Vec3f&, float area,
                                              const SampledWavelengths& lambda) const {
    // E / p_area.
    return irradiance_.Sample(lambda) * area;
}

double DirectionalLight::Power(const PhotonTarget& target) const {
    float w = MeanVisible(irradiance_);
    w *= target.area;
    return w;
}

}  // namespace nave::render
