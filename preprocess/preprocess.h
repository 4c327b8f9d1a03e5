#pragma once
// `nave preprocess` as a library call: inputs (model files or a generator) -> a brick store, in
// bounded memory. A plan first (preprocess_plan.h: the budget, brick size and threads, or a
// refusal), then the phases: read/bin, split (partition/partitioner.h), encode (several threads,
// store::EncodeBrick) and write (store::StoreWriter, atomic). The library changes nothing in the
// process (no signal handler, no limit): the caller does that. See docs/preprocess.md.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "store/store_writer.h"

namespace nave::preprocess {

/// Triangles per brick when none is asked for and the budget allows. Measured on the detail-110
/// abbey (docs/pager.md, "At scale"): with 700 k-triangle bricks the render stays within --memory
/// (2G: 59.0 s, 1G: 69.1 s, in-core 31.9 s); with 200 k ones it pages in about the same time (53.1
/// s, 67.0 s) but in-core takes 40.7 s and the process goes up to 307 MiB over --memory (Embree's
/// BVHs of many sizes fragment the heap). Preprocessing takes the same time (1 min 30 s).
inline constexpr uint64_t kDefaultBrickTriangles = 700'000;
/// The smallest brick size preprocess accepts.
inline constexpr uint64_t kMinBrickTriangles = 1000;

struct PreprocessOptions {
    /// Model files (merged), and at most one OpenVDB file (.vdb) whose grid `medium_grid` is the
    /// density of a participating medium, cut along the bricks (docs/preprocess.md, "Media").
    std::vector<std::filesystem::path> inputs;
    /// The medium's grid in the .vdb among `inputs` (`--medium-grid`); its world units are the
    /// model's.
    std::string medium_grid = "density";
    std::string generate;          ///< or a generator spec: "abbey:detail=D"
    std::filesystem::path output;  ///< the .nave store
    uint64_t memory_bytes = 0;     ///< budget; 0: a quarter of physical memory
    /// Target triangles per brick; 0: kDefaultBrickTriangles, or the largest size whose encoding
    /// work fits memory_bytes when that is less.
    uint64_t brick_triangles = 0;
    double precision = 0;            ///< grid step in model units; 0: bounds diagonal / 2^20
    int threads = 0;                 ///< 0: all hardware threads
    std::filesystem::path temp_dir;  ///< parent of the temporary directory; empty: beside output
    /// Encoder settings. Levels of detail are made only when `encode.levels.relative_errors` is
    /// not empty (`nave preprocess --levels`): docs/render.md, "Levels of detail", says why they
    /// are not made by default yet.
    store::EncodeOptions encode;
    /// Decode every n-th brick (and the first) after encoding to check it (EncodeOptions::verify);
    /// 1 checks them all, 0 none. `nave verify` checks a whole store later.
    uint32_t verify_every = 1;
    /// Convert the textures the materials name (texture_convert.h); false drops every texture slot.
    bool convert_textures = true;
    std::string tool_version = "nave";
    /// Set by the caller (its SIGINT / SIGTERM handler) to a signal number to stop the run; null:
    /// never stopped. Read only.
    const std::atomic<int>* interrupt = nullptr;
};

struct PreprocessStats {
    std::string source_name, units;
    std::string content;                ///< TriangleSource::content()
    uint64_t source_triangles = 0;      ///< triangles read from the input (after skipped bad faces)
    uint64_t stored_triangles = 0;      ///< triangles in bricks (crossing triangles once per brick)
    uint64_t duplicated_triangles = 0;  ///< references beyond the first of triangles crossing cells
    uint64_t collapsed_triangles = 0;   ///< dropped because the grid snapped two corners together
    uint64_t bricks = 0, empty_cells = 0, oversized_bricks = 0;
    uint64_t verified_bricks = 0;  ///< decoded and compared after encoding (verify_every)
    uint64_t output_bytes = 0, peak_temp_bytes = 0;
    /// Per level of detail (index k - 1 for level k): triangles and mesh-section bytes over all
    /// bricks.
    std::vector<uint64_t> level_triangles, level_bytes;
    double simplify_seconds = 0;  ///< thread time spent making levels (part of encode's)
    double grid_step = 0, max_error = 0;
    uint64_t memory_budget = 0, peak_rss = 0, source_memory = 0;
    int threads = 1;
    double seconds = 0, read_seconds = 0, split_seconds = 0, encode_seconds = 0;
    uint64_t textures_converted = 0, texture_bytes = 0;  ///< texture files written beside the store
    double texture_seconds = 0;
    /// The medium (a .vdb among the inputs; empty names: none): the grid's active voxels, those
    /// stored (a voxel whose cell crosses cells is stored in each), those dropped outside the
    /// model's box, the pieces' bytes, the bricks holding a piece and how many of them hold no
    /// triangles, and the largest density.
    std::string medium_file, medium_grid;
    uint64_t medium_voxels = 0, medium_stored_voxels = 0, medium_dropped_voxels = 0;
    uint64_t medium_bytes = 0, medium_bricks = 0, medium_only_bricks = 0;
    float medium_max_density = 0;
    /// The most the medium's cut held at once (volumes::GridCutSummary::peak_bytes).
    uint64_t medium_cut_peak_bytes = 0;
    std::vector<std::string> warnings;
};

/// Memory that converting textures adds to the run and keeps until its end: loading the OpenImageIO
/// plugin (libnave_oiio.so and its ~250 libraries) and its conversion buffers. Measured: the
/// abbey's glass maps raised the peak RSS of `nave preprocess --memory 64M` by 145 MB; larger
/// source images add their own float copy (width x height x channels x 4 bytes), which this does
/// not cover (docs/preprocess.md).
inline constexpr uint64_t kTextureConversionBytes = uint64_t(160) << 20;

/// Runs the whole preprocess: plans it (PlanPreprocess on this machine's resources), then reads,
/// splits, encodes and writes. Errors: bad options or a budget too small (the plan's refusals),
/// bad input (with file and line), I/O, Cancelled once `options.interrupt` holds a signal. On any
/// error nothing is left behind.
StatusOr<PreprocessStats> RunPreprocess(const PreprocessOptions& options);

/// The end-of-run summary, several lines.
std::string FormatSummary(const PreprocessStats& stats);

/// The default grid step for bounds of diagonal `diagonal`: diagonal / 2^20.
double DefaultGridStep(double diagonal);

}  // namespace nave::preprocess
