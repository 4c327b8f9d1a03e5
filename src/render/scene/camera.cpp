#include "src/render/scene/camera.h"

#include "src/core/sampling.h"

namespace nave::render {

Camera::Camera(const CameraConfig& c)
    : position_(c.position),
      width_(c.width),
      height_(c.height),
      tan_half_fov_(std::tan(c.fov_deg * 0.5f * kPi / 180.f)),
      aspect_(float(c.width) / float(c.height)),
      lens_radius_(c.lens_radius_m) {
    forward_ = Normalize(c.look_at - c.position);
    right_ = Normalize(Cross(forward_, c.up));
    up_ = Cross(right_, forward_);
    focus_distance_ = c.focus_distance_m > 0 ? c.focus_distance_m : Length(c.look_at - c.position);
}

void Camera::GenerateRay(float x, float y, float u_lens0, float u_lens1, Vec3f* origin,
                         Vec3f* dir) const {
    float sx = (2.f * x / float(width_) - 1.f) * tan_half_fov_ * aspect_;
    float sy = (1.f - 2.f * y / float(height_)) * tan_half_fov_;
    Vec3f d = Normalize(forward_ + right_ * sx + up_ * sy);
    if (lens_radius_ <= 0) {
        *origin = position_;
        *dir = d;
        return;
    }
    // Thin lens: every ray through the lens point meets the pinhole ray on the plane of focus.
    Vec3f focus = position_ + d * (focus_distance_ / Dot(d, forward_));
    Point2f l = SampleUniformDiskConcentric(Point2f(u_lens0, u_lens1));
    *origin = position_ + right_ * (l.x * lens_radius_) + up_ * (l.y * lens_radius_);
    *dir = Normalize(focus - *origin);
}

}  // namespace nave::render
