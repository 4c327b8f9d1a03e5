#include "src/render/scene/lights/point_light.h"

#include <cmath>

namespace nave::render {

std::optional<LightSample> PointLight::SampleLi(const Vec3f& p, Point2f,
                                                const SampledWavelengths& lambda) const {
    Vec3f d = position_ - p;
    float dist2 = Dot(d, d);
    if (dist2 == 0) return std::nullopt;
    float dist = std::sqrt(dist2);
    LightSample s;
    s.wi = d / dist;
    const float falloff = Falloff(-s.wi);
    // Intensity over the squared distance.
    s.weight = intensity_.Sample(lambda) * (falloff / dist2);
    s.t_max = dist * (1 - 1e-4f);
    return s;
}

PhotonSample PointLight::SamplePhoton(const PhotonRandoms& u,
                                      const SampledWavelengths& lambda) const {
    PhotonSample s;
    s.origin = position_;
    s.dir = SampleUniformSphere(u.u_direction);
    const float falloff = Falloff(s.dir);
    // I / p_dir with p_dir = 1 / (4 pi).
    s.power = intensity_.Sample(lambda) * (falloff * 4 * kPi);
    return s;
}

double PointLight::Power(const PhotonTarget&) const {
    // Φ = 4 pi I (for a spot, which sends less outside its cone, an upper bound).
    float w = MeanVisible(intensity_);
    w *= 4 * kPi;
    return w;
}

}  // namespace nave::render
