#pragma once
// Aiming photons from distant lights (sun, directional) at windows. Photons start on the
// projections of the portal triangles onto the plane perpendicular to the light. Where projections
// overlap (the windows of the north and the south walls seen along the sunlight), a point is
// reachable from several triangles: sampling a triangle by projected area and a point on it gives
// the density count(x) / A_total over the plane, where count(x) is the number of projections
// covering x (a one-sample balance-heuristic estimator over the portals, Veach 1997 §9.2), so the
// photon's power is L Omega A_total / count(x) and the flux through the union of the windows is
// unbiased. Light that enters elsewhere (open doors, gaps) or is reflected into a window from
// outside is on lines that cross no window: PhotonEmitters mixes these photons with photons through
// the whole model's disc (kPortalPhotonShare).

#include <array>
#include <cstdint>
#include <vector>

#include "src/core/vecmath.h"

namespace nave::render {

class PortalProjection {
  public:
    PortalProjection() = default;
    /// `to_light`: unit direction toward the light. Triangles edge-on to it are dropped.
    PortalProjection(const std::vector<std::array<Vec3f, 3>>& triangles, const Vec3f& to_light);

    bool empty() const { return cdf_.size() < 2; }
    /// Sum of the projected areas (m^2), overlaps counted as many times as they overlap.
    double total_area() const { return total_area_; }
    size_t triangle_count() const { return tris_.size(); }
    /// A point on a portal triangle chosen in proportion to projected area. (How many portals the
    /// photon's line crosses, count(x), PhotonEmitters counts with the portals' Embree scene.)
    Vec3f Sample(float u_choice, float u0, float u1) const;

  private:
    std::vector<std::array<Vec3f, 3>> tris_;
    std::vector<double> cdf_;
    double total_area_ = 0;
};

}  // namespace nave::render
