#pragma once
// What the medium tests count voxels by: whether a voxel's cell overlaps a box, for grids written
// with VdbPlugin::WriteScalarGrid (voxel ijk's cell is [origin + ijk voxel, origin + (ijk + 1)
// voxel]).

#include "src/core/vecmath.h"

namespace nave::test {

/// Voxel ijk's cell, of a grid of `voxel` voxels from `origin`, overlaps `box` (closed).
inline bool VoxelCellOverlaps(const Vec3f& origin, float voxel, int i, int j, int k,
                              const Bounds3f& box) {
    const int ijk[3] = {i, j, k};
    for (int a = 0; a < 3; ++a) {
        const float lo = origin[a] + float(ijk[a]) * voxel, hi = lo + voxel;
        if (hi < box.min[a] || lo > box.max[a]) return false;
    }
    return true;
}

}  // namespace nave::test
