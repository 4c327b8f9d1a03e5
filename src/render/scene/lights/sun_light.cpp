#include "src/render/scene/lights/sun_light.h"

namespace nave::render {

std::optional<LightSample> SunLight::SampleLi(const Vec3f&, Point2f u,
                                              const SampledWavelengths& lambda) const {
    // Uniform over the solar disc's cone (radiance constant over the disc: no limb darkening).
    LightSample s;
    s.wi = Sample(u);
    s.pdf = Pdf();
    s.weight = radiance_.Sample(lambda) / s.pdf;
    return s;
}

SampledSpectrum SunLight::PhotonPower(const Vec3f& to, float area,
                                      const SampledWavelengths& lambda) const {
    // L cos / (p_area p_dir) with p_dir = 1/Omega.
    return radiance_.Sample(lambda) * (Dot(to, to_light()) * area * float(SolidAngle()));
}

double SunLight::Power(const PhotonTarget& target) const {
    // The irradiance L Omega of the disc through the area photons start on.
    float w = MeanVisible(radiance_);
    w *= SolidAngle() * target.area;
    return w;
}

}  // namespace nave::render
