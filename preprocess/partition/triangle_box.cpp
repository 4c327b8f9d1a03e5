#include "preprocess/partition/triangle_box.h"

#include <algorithm>
#include <cmath>

namespace nave::preprocess {

bool TriangleOverlapsBox(const std::array<Vec3f, 3>& tri, const Bounds3d& box) {
    Vec3d c = (box.min + box.max) * 0.5, h = (box.max - box.min) * 0.5;
    Vec3d v[3] = {Vec3d(tri[0]) - c, Vec3d(tri[1]) - c, Vec3d(tri[2]) - c};
    // Box face normals: the triangle's extent against the box's along each axis.
    for (int a = 0; a < 3; ++a) {
        double lo = std::min({v[0][a], v[1][a], v[2][a]}),
               hi = std::max({v[0][a], v[1][a], v[2][a]});
        if (lo > h[a] || hi < -h[a]) return false;
    }
    Vec3d e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    // The nine axes edge x box axis.
    for (int i = 0; i < 3; ++i) {
        for (int a = 0; a < 3; ++a) {
            Vec3d axis;
            axis[a] = 1;
            Vec3d n = Cross(e[i], axis);
            if (Dot(n, n) == 0) continue;
            double p0 = Dot(v[0], n), p1 = Dot(v[1], n), p2 = Dot(v[2], n);
            double r = h.x * std::abs(n.x) + h.y * std::abs(n.y) + h.z * std::abs(n.z);
            if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r) return false;
        }
    }
    // The triangle's plane.
    Vec3d n = Cross(e[0], e[1]);
    double d = Dot(n, v[0]);
    double r = h.x * std::abs(n.x) + h.y * std::abs(n.y) + h.z * std::abs(n.z);
    return std::abs(d) <= r;
}

}  // namespace nave::preprocess
