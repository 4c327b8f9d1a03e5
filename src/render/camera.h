#pragma once
// A perspective camera with an optional thin lens. Raster (0, 0) is the top-left corner of the image.

#include <cmath>

#include "core/vecmath.h"
#include "render/scene_config.h"

namespace nave::render {

class Camera {
  public:
    explicit Camera(const CameraConfig& config);

    int width() const { return width_; }
    int height() const { return height_; }
    const Vec3f& position() const { return position_; }
    const Vec3f& forward() const { return forward_; }

    /// The primary ray through raster point (x, y) (continuous: pixel (i, j) spans [i, i+1) x [j, j+1)),
    /// with `u_lens` in [0,1)^2 choosing the point on the lens. `dir` is unit length.
    void GenerateRay(float x, float y, float u_lens0, float u_lens1, Vec3f* origin, Vec3f* dir) const;

  private:
    Vec3f position_, forward_, right_, up_;
    int width_, height_;
    float tan_half_fov_, aspect_;
    float lens_radius_, focus_distance_;
};

/// Maps [0,1)^2 to the unit disc preserving area (Shirley & Chiu, "A low distortion map between disk and
/// square", JGT 1997, concentric mapping).
inline void ConcentricSampleDisk(float u0, float u1, float* x, float* y) {
    float a = 2 * u0 - 1, b = 2 * u1 - 1;
    if (a == 0 && b == 0) {
        *x = *y = 0;
        return;
    }
    constexpr float kPiOver4 = 0.78539816339f, kPiOver2 = 1.57079632679f;
    float r, theta;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        theta = kPiOver4 * (b / a);
    } else {
        r = b;
        theta = kPiOver2 - kPiOver4 * (a / b);
    }
    *x = r * std::cos(theta);
    *y = r * std::sin(theta);
}

}  // namespace nave::render
