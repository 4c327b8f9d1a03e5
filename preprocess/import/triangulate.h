#pragma once
// Triangulation of the polygons OBJ and PLY faces may be. Convex polygons (the common case) become
// fans; concave ones (L-shaped CAD faces) are cut by ear clipping in the polygon's dominant plane
// (Newell normal, M. Newell 1972; ear clipping per Meisters, "Polygons have ears", 1975), which
// keeps every triangle inside the polygon and preserves its winding. Polygons over 256 corners, and
// self-intersecting ones where no ear exists, fall back to the fan.

#include <array>
#include <cstdint>
#include <vector>

#include "src/core/vecmath.h"

namespace nave::preprocess {

/// Appends triangles (indices into `corners`) covering the polygon `corners` to `out`.
void TriangulatePolygon(const std::vector<Vec3f>& corners,
                        std::vector<std::array<uint32_t, 3>>& out);

}  // namespace nave::preprocess
