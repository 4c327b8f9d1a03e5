#pragma once
// A perspective camera with an optional thin lens. Raster (0, 0) is the top-left corner of the
// image.

#include <cmath>

#include "src/core/vecmath.h"
#include "src/render/scene/scene_config.h"

namespace nave::render {

class Camera {
  public:
    explicit Camera(const CameraConfig& config);

    int width() const { return width_; }
    int height() const { return height_; }
    const Vec3f& position() const { return position_; }
    const Vec3f& forward() const { return forward_; }
    /// The angle one pixel subtends at the centre of the image, in radians (the spread of a pixel's
    /// ray cone).
    float PixelSpreadAngle() const { return 2.f * tan_half_fov_ / float(height_); }

    /// The primary ray through raster point (x, y) (continuous: pixel (i, j) spans [i, i+1) x [j,
    /// j+1)), with `u_lens` in [0,1)^2 choosing the point on the lens. `dir` is unit length.
    void GenerateRay(float x, float y, float u_lens0, float u_lens1, Vec3f* origin,
                     Vec3f* dir) const;

  private:
    Vec3f position_, forward_, right_, up_;
    int width_, height_;
    float tan_half_fov_, aspect_;
    float lens_radius_, focus_distance_;
};

}  // namespace nave::render
