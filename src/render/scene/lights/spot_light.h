#pragma once
// A spot light: a point light whose intensity is full inside an inner cone and falls off smoothly
// to zero at the outer one (pbrt-v4's SpotLight).

#include "src/render/scene/lights/point_light.h"

namespace nave::render {

class SpotLight final : public PointLight {
  public:
    /// A light at `position` shining along unit `axis` with `intensity` (W sr^-1 nm^-1) up to
    /// `cos_falloff` (the cosine of the falloff's start angle), falling to zero at `cos_cone`.
    SpotLight(const Vec3f& position, const Vec3f& axis, float cos_cone, float cos_falloff,
              Spectrum intensity)
        : PointLight(LightKind::kSpot, position, intensity),
          axis_(axis),
          cos_cone_(cos_cone),
          cos_falloff_(cos_falloff) {}

    const Vec3f& axis() const { return axis_; }

  protected:
    float Falloff(const Vec3f& w) const override;

  private:
    Vec3f axis_;  ///< the direction light travels
    float cos_cone_, cos_falloff_;
};

}  // namespace nave::render
