#include "render/photon_portals.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/sampling.h"

namespace nave::render {

PortalProjection::PortalProjection(const std::vector<std::array<Vec3f, 3>>& triangles, const Vec3f& to_light)
    : frame_(Frame::FromZ(to_light)) {
    float max_x = -INFINITY, max_y = -INFINITY;
    min_x_ = min_y_ = INFINITY;
    cdf_.push_back(0);
    for (const auto& t : triangles) {
        Tri2 p;
        p.v0 = t[0];
        p.v1 = t[1];
        p.v2 = t[2];
        p.ax = Dot(t[0], frame_.x), p.ay = Dot(t[0], frame_.y);
        p.bx = Dot(t[1], frame_.x), p.by = Dot(t[1], frame_.y);
        p.cx = Dot(t[2], frame_.x), p.cy = Dot(t[2], frame_.y);
        double area = 0.5 * std::abs(double(p.bx - p.ax) * (p.cy - p.ay) - double(p.cx - p.ax) * (p.by - p.ay));
        if (!(area > 1e-12)) continue;
        tris_.push_back(p);
        total_area_ += area;
        cdf_.push_back(total_area_);
        min_x_ = std::min({min_x_, p.ax, p.bx, p.cx});
        min_y_ = std::min({min_y_, p.ay, p.by, p.cy});
        max_x = std::max({max_x, p.ax, p.bx, p.cx});
        max_y = std::max({max_y, p.ay, p.by, p.cy});
    }
    if (tris_.empty()) return;
    for (double& c : cdf_) c /= total_area_;
    // A uniform grid over the projected box with about 4 triangles' worth of cells each, for Coverage().
    float w = std::max(1e-6f, max_x - min_x_), h = std::max(1e-6f, max_y - min_y_);
    cell_ = std::sqrt(w * h / float(std::max<size_t>(1, tris_.size() / 2)));
    nx_ = std::clamp(int(std::ceil(w / cell_)), 1, 1024);
    ny_ = std::clamp(int(std::ceil(h / cell_)), 1, 1024);
    cell_ = std::max(w / float(nx_), h / float(ny_));
    grid_.resize(size_t(nx_) * ny_);
    for (uint32_t i = 0; i < tris_.size(); ++i) {
        const Tri2& p = tris_[i];
        int x0 = std::clamp(int((std::min({p.ax, p.bx, p.cx}) - min_x_) / cell_), 0, nx_ - 1);
        int x1 = std::clamp(int((std::max({p.ax, p.bx, p.cx}) - min_x_) / cell_), 0, nx_ - 1);
        int y0 = std::clamp(int((std::min({p.ay, p.by, p.cy}) - min_y_) / cell_), 0, ny_ - 1);
        int y1 = std::clamp(int((std::max({p.ay, p.by, p.cy}) - min_y_) / cell_), 0, ny_ - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) grid_[size_t(y) * nx_ + x].push_back(i);
    }
}

bool PortalProjection::Contains(const Tri2& t, float x, float y) const {
    // Same-sign edge functions (either winding); points on an edge count as inside.
    auto edge = [](float ax, float ay, float bx, float by, float px, float py) {
        return double(bx - ax) * (py - ay) - double(by - ay) * (px - ax);
    };
    double e0 = edge(t.ax, t.ay, t.bx, t.by, x, y), e1 = edge(t.bx, t.by, t.cx, t.cy, x, y),
           e2 = edge(t.cx, t.cy, t.ax, t.ay, x, y);
    return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
}

int PortalProjection::Coverage(const Vec3f& p) const {
    float x = Dot(p, frame_.x), y = Dot(p, frame_.y);
    int gx = int((x - min_x_) / cell_), gy = int((y - min_y_) / cell_);
    if (gx < 0 || gy < 0 || gx >= nx_ || gy >= ny_) return 0;
    int n = 0;
    for (uint32_t i : grid_[size_t(gy) * nx_ + gx]) n += Contains(tris_[i], x, y) ? 1 : 0;
    return n;
}

Vec3f PortalProjection::Sample(float u_choice, float u0, float u1, int* coverage) const {
    size_t i = size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end(), double(u_choice)) - (cdf_.begin() + 1));
    i = std::min(i, tris_.size() - 1);
    const Tri2& t = tris_[i];
    // Uniform on the triangle; an affine projection keeps it uniform on the projection.
    const std::array<float, 3> w = SampleUniformTriangle(Point2f(u0, u1));
    Vec3f p = t.v0 * w[0] + t.v1 * w[1] + t.v2 * w[2];
    *coverage = std::max(1, Coverage(p));
    return p;
}

}  // namespace nave::render
