#pragma once
// Levels of detail of a brick: coarser versions of its mesh, made by edge collapse
// (meshoptimizer), for rays whose footprint is wider than the full mesh's detail (after diffuse
// bounces). docs/store-format.md, "Levels". No meshoptimizer type leaves brick_levels.cpp.

#include <vector>

#include "src/core/status.h"
#include "store/brick_mesh.h"

namespace nave::store {

/// Coarser versions of a brick's mesh: what preprocess stores beside each brick, and what tests and
/// procedural scenes build in memory.
struct LevelOptions {
    /// Triangles of each coarser level as a fraction of the full mesh's, coarsest last.
    std::vector<double> triangle_ratios = {0.1, 0.01};
    /// A level that keeps more than this fraction of the previous level's triangles is not made
    /// (nor any coarser one).
    double max_kept_fraction = 0.5;
};

/// One coarser version of a brick's mesh.
struct BrickLevel {
    BrickMesh mesh;
    /// Estimated largest distance, in model units, between this level's surface and the full
    /// mesh's (meshoptimizer's error, made absolute).
    float error = 0;
};

/// Checks `options`: every ratio in (0, 1), each smaller than the one before, max_kept_fraction in
/// (0, 1]. InvalidArgument naming the bad value otherwise.
Status ValidateLevelOptions(const LevelOptions& options);

/// Meshes with fewer triangles than this get no levels.
inline constexpr size_t kMinLevelSourceTriangles = 64;

/// The levels of `full`, finest first, each with a larger error than the one before. Thread-safe.
/// Empty when the mesh does not simplify (fewer than kMinLevelSourceTriangles triangles, or the
/// first level keeps too much). Every triangle keeps its material (edges collapse only within one
/// material's triangles); normals and texture coordinates are those of the vertices kept; borders,
/// those of the brick and those between materials, are not locked and move by up to the level's
/// error. `full` must satisfy ValidateBrickMesh; so does every level.
std::vector<BrickLevel> MakeBrickLevels(const BrickMesh& full, const LevelOptions& options = {});

}  // namespace nave::store
