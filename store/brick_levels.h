#pragma once
// Levels of detail of a brick: coarser versions of its mesh, made by edge collapse
// (meshoptimizer), for rays whose footprint is wider than the full mesh's detail (after diffuse
// bounces). docs/store-format.md, "Levels". No meshoptimizer type leaves brick_levels.cpp.

#include <cmath>
#include <cstdint>
#include <vector>

#include "src/core/status.h"
#include "store/brick_mesh.h"
#include "store/grid.h"

namespace nave::store {

/// Coarser versions of a brick's mesh: what preprocess stores beside each brick, and what tests and
/// procedural scenes build in memory.
struct LevelOptions {
    /// The error each coarser level aims at, as a fraction of the brick's extent (the diagonal of
    /// its geometry's box), finest first, each larger than the one before. Each level simplifies
    /// until the next collapse would pass its error: a level is as coarse as its error allows,
    /// wherever the brick's detail lies. Why 0.001 and 0.004 (a few cm and about 10 cm in the
    /// abbey's bricks): docs/store-format.md, "Levels".
    std::vector<double> relative_errors = {0.001, 0.004};
    /// A level that would keep more than this fraction of its source's triangles (the full mesh
    /// or the level before) is not made, and the next error is tried from the same source: such a
    /// level costs nearly as much to load and trace as its source, and takes store room. On a
    /// scanned model decimated already (the Stanford dragon's 100 k triangles) the first error
    /// kept 45 %, and made the store 42 % larger where the second error alone adds 8 %.
    double max_kept_fraction = 1.0 / 3.0;
    /// Which borders of each material's surface stay where they are. A brick holds every triangle
    /// crossing its cell, and the border where it was cut from its neighbours lies outside the
    /// cell: were it to recede by up to the level's error, holes would open inside the cell at
    /// its faces (a wall cut by a face would let light through at the coarse level:
    /// tests/render/levels_of_detail_test). Borders between materials, left free, would open
    /// cracks between them. The model's own open borders inside the cell (the ends of open
    /// strips, of mouldings and tracery made of separate sheets) slide along themselves, as
    /// meshoptimizer moves borders, within the level's error: locked too, they kept the
    /// detail-9 abbey's level 1 at 28.8 % of its triangles instead of 13.1 %
    /// (docs/store-format.md, "Levels").
    enum class BorderLock {
        kNone,             ///< every border slides along itself (small test surfaces)
        kEvery,            ///< every border stays (meshopt_SimplifyLockBorder)
        kCutAndMaterials,  ///< the brick's cut and the borders between materials stay
    };
    /// Without a cell (MakeBrickLevels' `cell`), kCutAndMaterials locks every border.
    BorderLock border_lock = BorderLock::kCutAndMaterials;
    /// The largest change, as a fraction, of a material's surface area in a brick that a level may
    /// make. Collapsing a part smaller than the error (a stud, a crocket, a finial) keeps the
    /// error small but takes the whole part's area away, and with it the light it stops: such a
    /// material is simplified toward halved errors until its area holds, or kept whole.
    double max_area_change = 0.02;
    /// Whether a level keeps its vertices' normals. A level's facets are larger than the full
    /// mesh's, and the full mesh's vertex normals, interpolated over them, bend far from them: a
    /// level is shaded with its facets' normals (docs/render.md, "Levels of detail"), and normals
    /// it stored would only take room (a third of a level's bytes on the abbey).
    bool keep_normals = false;
    /// A level's positions snap to a grid coarser than the store's, by a power of two, whose
    /// largest snapping distance (half a diagonal of its cell) is at most this fraction of the
    /// level's error, and which changes no material's area by more than half max_area_change
    /// (LevelGridShift): its positions then take fewer bits (0: the store's grid). The distance
    /// adds to the level's error.
    double max_grid_error_fraction = 0.1;
    /// Draco's encoder speed for levels (0, the smallest, to 10): levels are a tenth of a brick's
    /// triangles and load once per render when they stay resident, so their size matters more
    /// than their decoding speed.
    int draco_speed = 0;
};

/// One coarser version of a brick's mesh.
struct BrickLevel {
    BrickMesh mesh;
    /// Estimated largest distance, in model units, between this level's surface and the full
    /// mesh's (meshoptimizer's error, made absolute).
    float error = 0;
};

/// Checks `options`: every relative error in (0, 1), each larger than the one before,
/// max_kept_fraction in (0, 1], max_area_change in [0, 1). InvalidArgument naming the bad value
/// otherwise.
Status ValidateLevelOptions(const LevelOptions& options);

/// Meshes with fewer triangles than this get no levels.
inline constexpr size_t kMinLevelSourceTriangles = 64;

/// The levels of `full`, finest first, each with a larger error than the one before. Thread-safe.
/// Empty when the mesh does not simplify (fewer than kMinLevelSourceTriangles triangles, or the
/// first level keeps too much). Every triangle keeps its material (edges collapse only within one
/// material's triangles); normals and texture coordinates are those of the vertices kept; unless
/// options.border_lock is kNone the brick's cut and the borders between materials stay where
/// they are, so a level has no hole its brick's full mesh lacks. `cell` is the brick's cell,
/// where its cut lies; null for a mesh that stands alone (every border then stays). `full` must
/// satisfy ValidateBrickMesh; so does every level.
std::vector<BrickLevel> MakeBrickLevels(const BrickMesh& full, const LevelOptions& options = {},
                                        const Bounds3f* cell = nullptr);

/// The grid shift s (EncodeMeshSection) for `level`, whose error is `error`: the largest such that
/// every 2^s-th point of `grid` lies within options.max_grid_error_fraction * error of any point
/// (half its cell's diagonal), and that snapping there changes no material's area in the level by
/// more than half options.max_area_change. 0 when none coarser than the grid qualifies.
uint32_t LevelGridShift(const BrickMesh& level, float error, const GlobalGrid& grid,
                        const LevelOptions& options);

/// Half the diagonal of a cell of every 2^shift-th point of `grid`: the farthest a position moves
/// when snapped there.
inline double GridSnapDistance(const GlobalGrid& grid, uint32_t shift) {
    return 0.5 * std::sqrt(3.0) * grid.step * double(uint64_t(1) << shift);
}

}  // namespace nave::store
