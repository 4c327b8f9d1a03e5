#include "src/render/transport/photon_portals.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "src/core/sampling.h"
#include "src/render/scene/materials/frame.h"

namespace nave::render {

PortalProjection::PortalProjection(const std::vector<std::array<Vec3f, 3>>& triangles,
                                   const Vec3f& to_light) {
    const Frame frame = Frame::FromZ(to_light);
    cdf_.push_back(0);
    for (const auto& t : triangles) {
        // The area of the triangle projected on the plane facing the light.
        const float ax = Dot(t[0], frame.x), ay = Dot(t[0], frame.y);
        const float bx = Dot(t[1], frame.x), by = Dot(t[1], frame.y);
        const float cx = Dot(t[2], frame.x), cy = Dot(t[2], frame.y);
        double area = 0.5 * std::abs(double(bx - ax) * (cy - ay) - double(cx - ax) * (by - ay));
        if (!(area > 1e-12)) continue;
        tris_.push_back(t);
        total_area_ += area;
        cdf_.push_back(total_area_);
    }
    if (tris_.empty()) return;
    for (double& c : cdf_) c /= total_area_;
}

Vec3f PortalProjection::Sample(float u_choice, float u0, float u1) const {
    size_t i = size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end(), double(u_choice)) -
                      (cdf_.begin() + 1));
    i = std::min(i, tris_.size() - 1);
    const std::array<Vec3f, 3>& t = tris_[i];
    // Uniform on the triangle; an affine projection keeps it uniform on the projection.
    const std::array<float, 3> w = SampleUniformTriangle(Point2f(u0, u1));
    return t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
}

}  // namespace nave::render
