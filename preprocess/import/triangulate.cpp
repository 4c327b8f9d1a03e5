#include "preprocess/import/triangulate.h"

#include <cmath>

namespace nave::preprocess {
namespace {

struct P2 {
    double x, y;
};

double Cross2(const P2& o, const P2& a, const P2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

void Fan(size_t n, std::vector<std::array<uint32_t, 3>>& out) {
    for (uint32_t k = 1; k + 1 < n; ++k) out.push_back({0, k, k + 1});
}

}  // namespace

void TriangulatePolygon(const std::vector<Vec3f>& corners,
                        std::vector<std::array<uint32_t, 3>>& out) {
    const size_t n = corners.size();
    if (n < 3) return;
    if (n == 3 || n > 256) {
        Fan(n, out);
        return;
    }
    // Newell's normal: robust for non-planar and concave polygons.
    Vec3d normal;
    for (size_t i = 0; i < n; ++i) {
        Vec3d a(corners[i]), b(corners[(i + 1) % n]);
        normal.x += (a.y - b.y) * (a.z + b.z);
        normal.y += (a.z - b.z) * (a.x + b.x);
        normal.z += (a.x - b.x) * (a.y + b.y);
    }
    int axis = std::abs(normal.x) > std::abs(normal.y)
                   ? (std::abs(normal.x) > std::abs(normal.z) ? 0 : 2)
                   : (std::abs(normal.y) > std::abs(normal.z) ? 1 : 2);
    if (normal[axis] == 0) {
        Fan(n, out);
        return;
    }
    // Project dropping `axis`, ordered so that the polygon is counter-clockwise in 2D.
    int u = (axis + 1) % 3, v = (axis + 2) % 3;
    if (normal[axis] < 0) std::swap(u, v);
    std::vector<P2> p(n);
    for (size_t i = 0; i < n; ++i) p[i] = {double(corners[i][u]), double(corners[i][v])};
    bool convex = true;
    for (size_t i = 0; i < n && convex; ++i) {
        if (Cross2(p[i], p[(i + 1) % n], p[(i + 2) % n]) < 0) convex = false;
    }
    if (convex) {
        Fan(n, out);
        return;
    }
    std::vector<uint32_t> ring(n);
    for (uint32_t i = 0; i < n; ++i) ring[i] = i;
    while (ring.size() > 3) {
        bool clipped = false;
        const size_t m = ring.size();
        for (size_t i = 0; i < m; ++i) {
            uint32_t a = ring[(i + m - 1) % m], b = ring[i], c = ring[(i + 1) % m];
            if (Cross2(p[a], p[b], p[c]) <= 0) continue;  // reflex or flat corner: not an ear
            bool empty = true;
            for (uint32_t q : ring) {
                if (q == a || q == b || q == c) continue;
                if (Cross2(p[a], p[b], p[q]) >= 0 && Cross2(p[b], p[c], p[q]) >= 0 &&
                    Cross2(p[c], p[a], p[q]) >= 0) {
                    empty = false;
                    break;
                }
            }
            if (!empty) continue;
            out.push_back({a, b, c});
            ring.erase(ring.begin() + long(i));
            clipped = true;
            break;
        }
        if (!clipped) {
            // Self-intersecting or degenerate: fan what is left.
            for (size_t k = 1; k + 1 < ring.size(); ++k)
                out.push_back({ring[0], ring[k], ring[k + 1]});
            return;
        }
    }
    out.push_back({ring[0], ring[1], ring[2]});
}

}  // namespace nave::preprocess
