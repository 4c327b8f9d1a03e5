#pragma once
// A point light: light from one point, the same intensity in every direction (a delta light:
// next-event estimation only, never found by a path). The spot light is one whose intensity falls
// off outside a cone (spot_light.h).

#include "src/render/scene/lights/light.h"

namespace nave::render {

class PointLight : public Light {
  public:
    /// A light at `position` of `intensity` (W sr^-1 nm^-1) in every direction.
    PointLight(const Vec3f& position, Spectrum intensity)
        : PointLight(LightKind::kPoint, position, intensity) {}

    const Vec3f& position() const { return position_; }
    const Spectrum& intensity() const { return intensity_; }

    std::optional<LightSample> SampleLi(const Vec3f& p, Point2f u,
                                        const SampledWavelengths& lambda) const override;
    PhotonSample SamplePhoton(const PhotonRandoms& u,
                              const SampledWavelengths& lambda) const override;
    double Power(const PhotonTarget& target) const override;

  protected:
    PointLight(LightKind kind, const Vec3f& position, Spectrum intensity)
        : Light(kind), position_(position), intensity_(intensity) {}
    /// The share of the intensity sent along unit direction `w` (the way light travels): 1 here.
    virtual float Falloff(const Vec3f& w) const { return 1; }

  private:
    Vec3f position_;
    Spectrum intensity_;
};

}  // namespace nave::render
