#pragma once
// A directional light: parallel light from one direction, given by its irradiance on a surface
// facing it (a delta light: next-event estimation only, never found by a path).

#include "src/render/scene/lights/light.h"

namespace nave::render {

class DirectionalLight final : public DistantLight {
  public:
    /// Light travelling along unit direction `direction` with `irradiance` at normal incidence
    /// (W m^-2 nm^-1).
    DirectionalLight(const Vec3f& direction, Spectrum irradiance)
        : DistantLight(LightKind::kDirectional, -direction), irradiance_(irradiance) {}

    const Spectrum& irradiance() const { return irradiance_; }

    std::optional<LightSample> SampleLi(const Vec3f& p, Point2f u,
                                        const SampledWavelengths& lambda) const override;
    Vec3f SamplePhotonDirection(Point2f) const override { return to_light(); }
    SampledSpectrum PhotonPower(const Vec3f& to, float area,
                                const SampledWavelengths& lambda) const override;
    double Power(const PhotonTarget& target) const override;

  private:
    Spectrum irradiance_;
};

}  // namespace nave::render
