#include "src/render/scene/media/henyey_greenstein.h"

#include <algorithm>
#include <cmath>

#include "src/core/sampling.h"
#include "src/render/scene/materials/frame.h"

namespace nave::render {

float HenyeyGreenstein::Eval(float cos_theta) const {
    // Henyey & Greenstein 1941, eq. 3: (1 - g²) / (4π (1 + g² - 2 g cos θ)^(3/2)).
    const float denom = 1 + g_ * g_ - 2 * g_ * cos_theta;
    return (1 - g_ * g_) / (4 * kPi * denom * std::sqrt(std::max(denom, 1e-12f)));
}

PhaseSample HenyeyGreenstein::Sample(const Vec3f& dir, Point2f u) const {
    // The inverse of the cumulative distribution of cos θ (Pharr, Jakob & Humphreys, "Physically
    // Based Rendering", 4th ed., §11.3.1): cos θ = (1 + g² - ((1 - g²) / (1 - g + 2 g u))²) / (2g),
    // uniform in [-1, 1] when g is 0.
    float cos_theta;
    if (std::abs(g_) < 1e-3f) {
        cos_theta = 1 - 2 * u.x;
    } else {
        const float s = (1 - g_ * g_) / (1 - g_ + 2 * g_ * u.x);
        cos_theta = (1 + g_ * g_ - s * s) / (2 * g_);
    }
    cos_theta = std::clamp(cos_theta, -1.f, 1.f);
    const float sin_theta = std::sqrt(std::max(0.f, 1 - cos_theta * cos_theta));
    const float phi = 2 * kPi * u.y;
    const Frame frame = Frame::FromZ(dir);
    const Vec3f wi = frame.x * (sin_theta * std::cos(phi)) + frame.y * (sin_theta * std::sin(phi)) +
                     frame.z * cos_theta;
    return {Normalize(wi), Eval(cos_theta)};
}

}  // namespace nave::render
