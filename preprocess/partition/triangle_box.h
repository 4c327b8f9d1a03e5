#pragma once
// Exact triangle / axis-aligned box overlap by the separating axis theorem: the 3 box normals, the
// triangle's normal and the 9 cross products of triangle edges with box axes (T. Akenine-Moeller,
// "Fast 3D Triangle-Box Overlap Testing", Journal of Graphics Tools 6(1), 2001). In double
// precision; touching counts as overlapping.

#include <array>

#include "src/core/vecmath.h"

namespace nave::preprocess {

bool TriangleOverlapsBox(const std::array<Vec3f, 3>& triangle, const Bounds3d& box);

}  // namespace nave::preprocess
