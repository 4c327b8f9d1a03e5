#include "src/render/scene/lights/spot_light.h"

#include <algorithm>

namespace nave::render {

float SpotLight::Falloff(const Vec3f& w) const {
    // Smoothstep between the cone and the start of the falloff (pbrt-v4 SpotLight::I).
    float cos_a = Dot(w, axis_);
    float x = std::clamp((cos_a - cos_cone_) / std::max(1e-6f, cos_falloff_ - cos_cone_), 0.f, 1.f);
    return x * x * (3 - 2 * x);
}

}  // namespace nave::render
