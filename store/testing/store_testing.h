#pragma once
// Synthetic meshes and small stores for tests and benchmarks, so that they need no importer. Not
// part of the `nave` executable (library nave_store_testing).

#include <filesystem>
#include <vector>

#include "src/core/status.h"
#include "store/brick_mesh.h"
#include "store/brick_tree.h"
#include "store/material_record.h"
#include "store/store_writer.h"

namespace nave::store::testing {

/// A wavy height field z = a sin(x) cos(y) over [0, size_m]^2, tessellated into quads_x * quads_y
/// quads of two triangles each, with analytic unit normals, UVs in [0, 1]^2 and material ids in
/// vertical bands.
struct SurfaceOptions {
    uint32_t quads_x = 32;
    uint32_t quads_y = 32;
    float size_m = 10.f;
    float amplitude_m = 0.5f;
    uint32_t material_count = 3;
    bool normals = true;
    bool uvs = true;
    /// Irregular tessellation: interior vertices move by up to +-jitter/2 of a quad in x and y, and
    /// each quad takes a random diagonal (seeded by `seed`). 0 gives the regular grid.
    float jitter = 0.f;
    uint32_t seed = 1;
};
BrickMesh MakeSurface(const SurfaceOptions& options);

/// `count` materials named "m0", "m1"... with distinct colours and one texture slot on the odd
/// ones.
std::vector<MaterialRecord> MakeMaterials(uint32_t count);

/// A store cut from one mesh on a regular grid of cells (triangles go to the cell of their
/// centroid; each brick has its own copy of the vertices it uses, so vertices on a cell border
/// appear in several bricks).
struct GridStore {
    BrickTree tree;                                ///< leaves are the non-empty cells, by brick id
    std::vector<BrickMesh> bricks;                 ///< the input of each brick, by brick id
    std::vector<std::vector<uint32_t>> triangles;  ///< source triangle of each brick triangle
};

/// Splits `mesh` into `cells` (x, y, z counts) over its bounds, encodes every non-empty cell with
/// `options` and writes the store to `path` with `materials`.
StatusOr<GridStore> WriteGridStore(const std::filesystem::path& path, const BrickMesh& mesh,
                                   const std::vector<MaterialRecord>& materials, Vec3i cells,
                                   const GlobalGrid& grid, const EncodeOptions& options = {});

/// Splits `mesh` as WriteGridStore does, without writing anything (`tree` leaves name brick ids).
GridStore SplitOnGrid(const BrickMesh& mesh, Vec3i cells);

}  // namespace nave::store::testing
