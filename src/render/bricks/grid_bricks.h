#pragma once
// Cutting one mesh into a regular grid of bricks in memory, for models that never went through
// preprocess: the procedural scenes (`nave render --procedural`), tests and benchmarks.

#include <vector>

#include "store/brick_mesh.h"
#include "store/brick_tree.h"

namespace nave::render {

/// The bricks of a grid split: a kd-tree whose leaves name brick ids, and each brick's mesh by id.
struct GridBricks {
    store::BrickTree tree;
    std::vector<store::BrickMesh> meshes;
};

/// Cuts `mesh` into an nx * ny * nz grid of bricks over its bounds (slightly enlarged), as
/// preprocess does: every triangle goes to every cell its box overlaps, and empty cells get no
/// brick. Each brick keeps its own copy of the vertices it uses (with their normals and UVs).
GridBricks SplitIntoGridBricks(const store::BrickMesh& mesh, int nx, int ny, int nz);

}  // namespace nave::render
