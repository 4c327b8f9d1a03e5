#pragma once
// What the ray streams did during one render: rays and segments traced, rays moved between bricks,
// batches, bricks loaded and evicted, queues spilled, the brick cache. Filled by the scheduler
// (StreamScheduler::FillStats); the render's own facts extend it (integrators/render_stats.h).

#include <cstdint>

#include "src/render/stream/pager.h"
#include "src/render/stream/ray_exchange.h"

namespace nave::render {

struct StreamStats {
    uint64_t rays = 0;             ///< rays started: camera, continuation, shadow rays and photons
    uint64_t segments_traced = 0;  ///< ray segments traced inside a brick (closest-hit queries)
    uint64_t shadow_segments =
        0;  ///< shadow-ray segments traced inside a brick (occlusion queries)
    uint64_t brick_moves =
        0;                 ///< rays queued at another brick (crossed a cell face or spawned there)
    uint64_t batches = 0;  ///< times the scheduler gave the workers a brick's waiting rays
    uint64_t bytes_read = 0;  ///< bytes the brick source read from the store
    /// Bricks in memory (docs/pager.md): the pager's counts. In-core: no budget (0), no evictions.
    PagerStats residency;
    uint64_t peak_queue_bytes = 0;
    // The brick cache under a budget (BrickCache): bricks written, reloads it served, its size on
    // disk and decoded.
    uint64_t brick_cache_written = 0;
    uint64_t brick_cache_reads = 0;
    uint64_t brick_cache_disk_bytes = 0;
    uint64_t brick_cache_mesh_bytes = 0;
    // Ray queues spilled to disk under a budget: rays written, bytes written (compressed) and the
    // most the spill file held at once.
    uint64_t spilled_rays = 0;
    uint64_t spill_bytes_written = 0;
    uint64_t spill_peak_disk_bytes = 0;
    // A distributed render (docs/distributed.md): its processes, and what their exchange did,
    // summed over them (the counts above are summed too; residency is this process's).
    int ranks = 1;
    ExchangeCounts exchange;
    int rebalances = 0;  ///< times the bricks went to new owners (StreamScheduler::Rebalance)
    /// Rounds of a render that learns in rounds which began while rays of the round before were
    /// still in flight (StreamScheduler::DrainRoundsBefore).
    int rounds_overlapped = 0;
};

}  // namespace nave::render
