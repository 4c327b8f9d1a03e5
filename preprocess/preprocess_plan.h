#pragma once
// What a preprocess run will do, decided before it does anything: the memory budget and how it is
// shared (a fixed part, one brick's encoding work, texture conversion, the split's buffers), the
// brick size, the threads, the grid. Every function here is pure: it reads only its arguments
// (the machine's resources are read once, by QueryMachineResources, and passed in), so each
// refusal can be tested without running anything. A refusal names the option to change, what it
// was and what would do.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "preprocess/partition/partitioner.h"
#include "preprocess/preprocess.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "store/grid.h"

namespace nave::preprocess {

/// Memory the run needs besides the bricks being encoded: the reading batch, the root bin's block
/// buffers, the sample, the split buffers per thread, and a margin for the allocator and libraries.
inline constexpr uint64_t kFixedBytes = 48ull << 20;

/// What the machine offers a run. Read by QueryMachineResources; tests make their own.
struct MachineResources {
    uint64_t physical_memory_bytes = 0;
    int hardware_threads = 1;
    /// The soft limit of open files (RLIMIT_NOFILE). `nave preprocess` raises it to the hard limit
    /// before planning; a library caller gets what its process has.
    uint64_t open_files = 1024;
};

/// This machine's and this process's resources. Reads them only: changes no limit.
MachineResources QueryMachineResources();

/// The decisions a run takes from its options alone.
struct PreprocessPlan {
    uint64_t memory_budget = 0;  ///< bytes; --memory, or a quarter of physical memory
    int threads = 1;             ///< --threads, or every hardware thread
    /// Target triangles per brick: --brick-triangles, or the default, or less when the budget
    /// cannot hold the default's work (then `brick_triangles_fitted`).
    uint64_t brick_triangles = 0;
    bool brick_triangles_fitted = false;
    uint64_t leaf_max_triangles = 0;  ///< the largest a leaf may be (LeafMaxTriangles)
    uint64_t brick_work_bytes = 0;    ///< encoding work of such a leaf
    /// Producer threads of a generator: each buffers about 10 MiB of triangles, so small budgets
    /// get one.
    int generator_producers = 1;
    /// The split's configuration (threads, buffers, fan-out); its `interrupt` is left to the run.
    PartitionConfig partition;
    std::filesystem::path temp_parent;  ///< where the run's temporary directory goes
    /// The inputs split: model files, and the medium's .vdb (empty: none).
    std::vector<std::filesystem::path> models;
    std::filesystem::path medium;
};

/// The plan for `options` on `machine`, or InvalidArgument naming the option and what was expected
/// (no model or both models and a generator, two .vdb files (naming both), no output,
/// --brick-triangles under kMinBrickTriangles, a negative --precision), or ResourceExhausted when
/// --memory cannot hold the work of one brick (with the numbers, the --memory that would, and the
/// largest --brick-triangles that fits).
StatusOr<PreprocessPlan> PlanPreprocess(const PreprocessOptions& options,
                                        const MachineResources& machine);

/// Memory to set aside for converting textures (kTextureConversionBytes: OpenImageIO stays loaded
/// to the end of the run), or ResourceExhausted when the budget cannot hold it beside one brick's
/// work (naming --memory and --no-textures).
StatusOr<uint64_t> PlanTextureReserve(const PreprocessPlan& plan);

/// The grid bricks are quantized to and the brick tree's root cell.
struct GridPlan {
    store::GlobalGrid grid;
    Bounds3f root;     ///< the bounds grown by a grid step, so snapped positions stay inside
    double max_error;  ///< the largest distance snapping moves a point: step * sqrt(3) / 2
};

/// The grid for a model of bounds `bounds`: step `precision`, or DefaultGridStep of the diagonal
/// when 0. InvalidArgument when the model is more than 2^29 steps across (naming --precision and
/// the smallest step that fits).
StatusOr<GridPlan> PlanGrid(double precision, const Bounds3d& bounds);

/// How the encode phase shares the budget.
struct EncodePlan {
    uint64_t budget = 0;        ///< memory for encoding work: the budget less the fixed part and
                                ///< the texture reserve
    uint64_t largest_leaf = 0;  ///< triangles of the largest leaf
    int threads = 1;            ///< encoding threads: as many as the budget holds, at most plan's
};

/// The encode phase's share of the budget for `leaves`, after `texture_reserve` was set aside, or
/// ResourceExhausted naming the first leaf whose work the budget cannot hold (its triangles and
/// cell, and the --memory that would).
StatusOr<EncodePlan> PlanEncode(const PreprocessPlan& plan, uint64_t texture_reserve,
                                const std::vector<LeafBin>& leaves);

}  // namespace nave::preprocess
