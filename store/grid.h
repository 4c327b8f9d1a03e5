#pragma once
// The store's global position grid. Every position is snapped to origin + step * (i, j, k) with
// integer i, j, k before encoding, so a vertex shared by two bricks decodes to the same coordinates
// in both (no cracks between bricks). The largest error per axis is step / 2, so at most step *
// sqrt(3) / 2 in length.

#include <cmath>
#include <cstdint>

#include "src/core/vecmath.h"

namespace nave::store {

struct GlobalGrid {
    Vec3d origin;     ///< the grid point (0, 0, 0), in world units
    double step = 0;  ///< grid spacing, in world units (metres for nave's models)

    Vec3i Quantize(const Vec3f& p) const {
        return {int32_t(std::llround((double(p.x) - origin.x) / step)),
                int32_t(std::llround((double(p.y) - origin.y) / step)),
                int32_t(std::llround((double(p.z) - origin.z) / step))};
    }
    Vec3f Dequantize(const Vec3i& q) const {
        return {float(origin.x + double(q.x) * step), float(origin.y + double(q.y) * step),
                float(origin.z + double(q.z) * step)};
    }
    /// Bound on |decoded - original| along one axis (plus float rounding of the decoded value).
    double MaxAxisError() const { return 0.5 * step; }
};

/// The geometric normal of a triangle of grid points, times twice its area (in grid steps^2), in
/// double from the integer differences: every step that judges or recomputes normals on snapped
/// positions (preprocess, the store's encoder and decoder) gets the same answer.
inline Vec3d GridNormal(const Vec3i& a, const Vec3i& b, const Vec3i& c) {
    const Vec3d e1(double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z);
    const Vec3d e2(double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z);
    return Cross(e1, e2);
}

}  // namespace nave::store
