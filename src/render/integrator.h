#pragma once
// Rendering with ray streams over bricks (the domain decomposition of the origin paper). Every ray
// in flight
// - camera path, continuation, shadow ray, photon - is a compact record waiting in the queue of the
// brick its next segment lies in. The scheduler repeatedly picks the brick with the most rays
// waiting, pins it through the BrickSource, and all threads trace that brick's batch inside the
// brick's cell; hits are shaded with the brick's own data and every spawned ray, or ray leaving the
// cell, is queued at the next brick along it. Nothing assumes that a brick not pinned is resident.
//
// Determinism: every random number of a ray is a hash of (seed, pixel, sample, depth, iteration),
// and the film sums in double, so the image does not depend on the number of bricks, the processing
// order or the thread count beyond double-precision summation order (relative 1e-12 on a pixel,
// bound tested) and float differences of hits found in different bricks (none in the tests: same
// triangles, same rays).

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/render/film.h"
#include "src/render/pager.h"
#include "src/render/render_session.h"
#include "src/render/scene.h"

namespace nave::render {

/// What a render did, for the final summary and the EXR metadata.
struct RenderStats {
    double wall_seconds = 0;
    uint64_t camera_paths = 0;
    uint64_t rays = 0;  ///< rays started: camera, continuation, shadow rays and photons

    uint64_t segments_traced = 0;  ///< ray segments traced inside a brick (closest-hit queries)
    uint64_t shadow_segments =
        0;                 ///< shadow-ray segments traced inside a brick (occlusion queries)
    uint64_t photons = 0;  ///< photons emitted
    uint64_t brick_moves =
        0;                 ///< rays queued at another brick (crossed a cell face or spawned there)
    uint64_t batches = 0;  ///< times the scheduler gave the workers a brick's waiting rays
    uint64_t bytes_read = 0;
    /// Bricks in memory (docs/pager.md): the pager's counts. In-core: no budget (0), no evictions,
    /// stall = time the scheduler waited for loads.
    PagerStats residency;
    uint64_t peak_rss_bytes = 0;
    uint64_t peak_queue_bytes = 0;
    // The brick cache under a budget (BrickMeshCache): meshes written, loads it served, its size
    // on disk and decoded.
    uint64_t cache_bricks_written = 0;
    uint64_t cache_reads = 0;
    uint64_t cache_disk_bytes = 0;
    uint64_t cache_mesh_bytes = 0;
    // Ray queues spilled to disk under a budget: rays written, bytes written (compressed) and the
    // most the spill file held at once.
    uint64_t spilled_rays = 0;
    uint64_t spill_bytes_written = 0;
    uint64_t spill_peak_disk_bytes = 0;
    /// The render's own estimate of its image's relative mean squared error (luminance), from its
    /// two halves of samples (docs/render.md, "Noise"); NaN with fewer than two passes or
    /// iterations.
    double noise_relmse = 0;
    int samples_per_pixel = 0;  ///< path mode: passes completed
    int iterations = 0;         ///< photon mode: SPPM iterations completed
    /// Path mode with render.path_guiding: the guide's cells with histograms, and those guiding.
    uint32_t guide_cells = 0;
    uint32_t guide_cells_guiding = 0;
};

/// The scheduling policy: which brick to process next, given the rays waiting in every brick's
/// queue (indexed by brick id; never called with all queues empty). Return a brick with waiting
/// rays. The default picks the brick with the most rays waiting (the paper's load balancing); the
/// out-of-core pager replaces it to weigh residency and prefetching. Called from the scheduler
/// thread only.
using BrickPicker =
    std::function<uint32_t(const std::vector<size_t>& waiting, const BrickSource& source)>;

/// The default policy: the most rays waiting, lowest id on ties.
uint32_t PickFullestBrick(const std::vector<size_t>& waiting, const BrickSource& source);

/// Renders `scene` into `film` in the mode of scene.settings. `film` must match the camera's
/// resolution. Thread count: scene.settings.threads (0: all cores). `picker` empty: the pager's
/// choice (the fullest resident brick first). `paging` null: in-core with the default tunables
/// (bricks stay once loaded, and are loaded in the background while the workers trace); else bricks
/// are paged under paging->brick_budget_bytes (pager.h; kUnlimitedBrickBudget is in-core), and an
/// impossible budget is refused before anything is traced. `session` (null: one run from the start)
/// continues from a checkpoint, writes checkpoints and may end the run early (render_session.h).
Status RenderStreams(const RenderScene& scene, Film* film, RenderStats* stats,
                     BrickPicker picker = {}, const PagerOptions* paging = nullptr,
                     const SessionOptions* session = nullptr);

}  // namespace nave::render
