#pragma once
// Sampling of directions and discs for Monte Carlo rendering. Header-only; every warp lists its
// pdf.

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "src/core/vecmath.h"

namespace nave {

/// A pair of uniform random numbers in [0, 1)² (or a 2D point in general).
struct Point2f {
    float x = 0, y = 0;
    constexpr Point2f() = default;
    constexpr Point2f(float x_, float y_) : x(x_), y(y_) {}
    constexpr float operator[](int i) const { return i == 0 ? x : y; }
    constexpr bool operator==(const Point2f&) const = default;
};

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = std::numbers::inv_pi_v<float>;

/// Concentric map of the square to the unit disc (Shirley & Chiu 1997, "A low distortion map
/// between disk and square"), area-preserving.
inline Point2f SampleUniformDiskConcentric(Point2f u) {
    float ox = 2.f * u.x - 1.f, oy = 2.f * u.y - 1.f;
    if (ox == 0.f && oy == 0.f) return {0.f, 0.f};
    float r, theta;
    if (std::abs(ox) > std::abs(oy)) {
        r = ox;
        theta = (kPi / 4.f) * (oy / ox);
    } else {
        r = oy;
        theta = kPi / 2.f - (kPi / 4.f) * (ox / oy);
    }
    return {r * std::cos(theta), r * std::sin(theta)};
}

/// Cosine-weighted direction on the hemisphere z > 0 (Malley's method); pdf cosθ/π.
inline Vec3f SampleCosineHemisphere(Point2f u) {
    Point2f d = SampleUniformDiskConcentric(u);
    float z = std::sqrt(std::max(0.f, 1.f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}
inline float CosineHemispherePdf(float cos_theta) { return cos_theta * kInvPi; }

/// Barycentric weights of a point uniform on a triangle (Turk 1990's square-root parameterisation,
/// "Generating random points in triangles", Graphics Gems): the point is b[0] v0 + b[1] v1 + b[2]
/// v2; pdf 1/area.
inline std::array<float, 3> SampleUniformTriangle(Point2f u) {
    const float su = std::sqrt(u.x);
    return {1.f - su, su * (1.f - u.y), su * u.y};
}

/// Uniform direction on the unit sphere; pdf 1/(4π).
inline Vec3f SampleUniformSphere(Point2f u) {
    float z = 1.f - 2.f * u.x;
    float r = std::sqrt(std::max(0.f, 1.f - z * z));
    float phi = 2.f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float UniformSpherePdf() { return 1.f / (4.f * kPi); }

/// Uniform direction in the cone of half-angle acos(cos_theta_max) around +z; pdf 1/(2π(1 -
/// cosθmax)). Used for the sun's disc.
inline Vec3f SampleUniformCone(Point2f u, float cos_theta_max) {
    float cos_theta = (1.f - u.x) + u.x * cos_theta_max;
    float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    float phi = u.y * 2.f * kPi;
    return {std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta};
}
inline float UniformConePdf(float cos_theta_max) {
    return 1.f / (2.f * kPi * (1.f - cos_theta_max));
}

/// 1 - cos θ for a narrow cone, without cancellation: 2 sin²(θ/2).
inline double OneMinusCos(double theta) {
    const double s = std::sin(0.5 * theta);
    return 2 * s * s;
}
/// Uniform direction in the cone of half-angle `theta_max` (radians) around +z, for narrow cones
/// such as the sun's 0.27°, where cos θmax in float takes only ~180 values over the disc: 1 - cos θ
/// is drawn in double and sin θ computed from it. Pdf: UniformNarrowConePdf.
inline Vec3f SampleUniformNarrowCone(Point2f u, double theta_max) {
    const double one_minus_cos = double(u.x) * OneMinusCos(theta_max);
    const double sin_theta = std::sqrt(std::max(0.0, one_minus_cos * (2 - one_minus_cos)));
    const double phi = double(u.y) * 2 * std::numbers::pi;
    return {float(std::cos(phi) * sin_theta), float(std::sin(phi) * sin_theta),
            float(1 - one_minus_cos)};
}
/// The solid angle of a cone of half-angle `theta_max`, 2π(1 - cos θmax), in double.
inline double ConeSolidAngle(double theta_max) {
    return 2 * std::numbers::pi * OneMinusCos(theta_max);
}
/// Whether unit direction `w` lies within `theta_max` of unit `axis`, from sin² of their angle
/// (|w × axis|²), which keeps its precision for narrow cones where their cosine does not.
inline bool InNarrowCone(const Vec3f& w, const Vec3f& axis, double theta_max) {
    const Vec3f c = Cross(w, axis);
    const double s = std::sin(theta_max);
    return Dot(w, axis) > 0 && double(Dot(c, c)) <= s * s;
}

}  // namespace nave
