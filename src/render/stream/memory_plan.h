#pragma once
// How `nave render --memory` splits its budget (docs/pager.md): the texture cache's share, the ray
// queues kept in memory, a reserve for the film, the queues of a wave, the process, a checkpoint's
// state and the scratch of one brick's load, and the bricks get what is left. A budget that cannot
// hold the largest bricks beside the reserve, or the image writer afterwards, is refused here with
// the numbers that show why. Pure arithmetic over inputs measured beforehand, so that every share
// and every refusal can be tested without rendering. Every piece of budget arithmetic of a render
// is here: the queue memory, the batch size, the wave size and the reserve, each from one base.
// What the film and the light transport hold is measured by the rooms above (RenderStateBytes,
// filled by integrators/render_memory.h); the plan only adds it up.

#include <cstdint>
#include <optional>
#include <string>

#include "src/core/status.h"
#include "src/render/scene/scene_config.h"
#include "src/render/stream/pager.h"
#include "src/render/stream/ray.h"

namespace nave::render {

/// The texture cache's cap: [textures] cache without a budget, else the share
/// [textures] memory_share of `memory_bytes` (--memory), which the plan then counts as reserved.
uint64_t TextureCacheCapBytes(const TextureConfig& textures, std::optional<uint64_t> memory_bytes);
/// The most a texture cache needs once its textures are open, `opened_pixel_bytes` of them
/// decoded: twice that, for the cache's own bookkeeping and tiles in flight, plus 4 MiB. A cap
/// above it buys nothing and, under --memory, would only take room from the bricks.
uint64_t TextureCacheEnoughBytes(uint64_t opened_pixel_bytes);

/// The queue memory of `paging`: its queue_memory_bytes, or with kAutoQueueMemory 1/32 of the
/// whole process's budget (memory_bytes, --memory), at least 32 MiB.
uint64_t QueueMemoryBytes(const PagerOptions& paging);
/// Rays taken from a queue per batch: at most 256 k, and under a queue memory cap (0: none) few
/// enough that the batch and the two rays each of its rays may send on stay within the cap.
size_t MaxBatchRays(uint64_t queue_memory_bytes);
/// The camera paths per wave when paging with spilled queues and the user chose none: the whole
/// image (all its passes) in one wave, at most kMaxPagedWavePaths. One wave has one tail, the few
/// deep bounces scattered over every brick that cost a load each; the camera rays of a wave beyond
/// the queue memory spill as they are generated (docs/pager.md). Path mode only: photon mode's
/// camera and photon passes are drained separately each iteration anyway.
inline constexpr uint64_t kMaxPagedWavePaths = uint64_t(16) << 20;
uint32_t WavePathsUnderPaging(const RenderSettings& settings, int width, int height);

/// What a render grows the process by beyond its size when planned, bricks, film and queues aside:
/// Embree's and TBB's threads and state, allocator slack (an 8x8 render of a one-brick model: 3
/// MiB).
inline constexpr uint64_t kRenderGrowthBytes = uint64_t(32) << 20;
/// What writing the image adds once the render is over and its bricks and queues are freed:
/// OpenImageIO and the libraries it loads (measured 122 MiB on Debian 12). --memory must hold the
/// process, the film and this.
inline constexpr uint64_t kImageWriterBytes = uint64_t(128) << 20;

/// What a render holds beside bricks, ray queues and the process, as the rooms above the streams
/// measure it (RenderStateMemory in integrators/render_memory.h).
struct RenderStateBytes {
    uint64_t film = 0;        ///< the film's sums (Film::MemoryBytes)
    uint64_t transport = 0;   ///< photon mode's visible points and learning, path mode's guide
    uint64_t checkpoint = 0;  ///< writing a checkpoint, beside the render; 0: no checkpoints
};

/// What a render's memory plan is made from: the user's budget, the render, and what was measured
/// of the model and the process just before planning.
struct RenderMemoryInputs {
    uint64_t memory_bytes = 0;  ///< --memory in bytes: the whole process's budget
    std::string memory_text;    ///< --memory as the user wrote it ("620M"), for messages
    RenderSettings settings;    ///< the render's settings (the plan may choose wave_paths)
    int width = 0;              ///< the image's, in pixels
    int height = 0;
    RenderStateBytes state;  ///< the film's, the light transport's and a checkpoint's memory
    /// The pager's tunables: prefetch, wave_overlap, queue_memory_bytes (kAutoQueueMemory: a share
    /// of the budget).
    PagerOptions pager;
    uint32_t brick_count = 0;
    BrickBudgetMinimum bricks;        ///< MinimumBrickBudget of the model under pager.prefetch
    uint64_t load_scratch_bytes = 0;  ///< the most one brick's load needs beside the brick
    /// The bricks' occupancy grids (BrickSource::Occupancy), each kept once its brick is loaded;
    /// 0 unless the source knows them (BrickSource::occupancy_known) or pager.skip_air is on.
    uint64_t occupancy_bytes = 0;
    /// The process's resident size when the render is planned (code, libraries, the store's
    /// tables, the scene, the texture system if loaded).
    uint64_t process_bytes = 0;
    uint64_t texture_cache_bytes = 0;  ///< the texture cache's cap; 0: no texture cache
    /// Whether OpenImageIO is loaded already (by the texture cache): its memory is then part of
    /// process_bytes and writing the image adds nothing for it.
    bool image_library_loaded = false;

    /// The inputs of a render over `source` with `pager`'s tunables: the bricks' sizes under its
    /// prefetch setting, the largest load's scratch and the process's current resident size. The
    /// rest is the caller's to fill in. Call after the source's BVH settings are final (they
    /// change the bricks' sizes) and after everything the render holds besides bricks is loaded.
    static RenderMemoryInputs Measure(const BrickSource& source, const PagerOptions& pager);
};

/// Memory the render needs beside bricks and beside what RenderMemoryPlan::Make adds (texture
/// cache, load scratch, checkpoint): the process (`inputs.process_bytes` plus kRenderGrowthBytes
/// and a little per brick), the film and the light transport's state (`inputs.state`), and the ray
/// queues of waves of `settings.wave_paths`, capped by `queue_memory_bytes` (0: no spilling, the
/// queues of a wave are all in memory) and its batches.
uint64_t RenderReserveBytes(const RenderMemoryInputs& inputs, const RenderSettings& settings,
                            uint64_t queue_memory_bytes);

/// The split of one --memory budget. Copyable; Apply hands it to the pager and the render.
class RenderMemoryPlan {
  public:
    /// Plans `inputs`: ray queues (PagerOptions::queue_memory_bytes, QueueMemoryBytes of the
    /// budget unless the user chose), the reserve (RenderReserveBytes plus the texture cache, the
    /// largest load's scratch and a checkpoint's state) and the brick budget (the rest). When the
    /// bricks will not all fit and queues spill, path mode renders one wave of the whole image
    /// unless the user chose (WavePathsUnderPaging). Errors: ResourceExhausted naming --memory as
    /// given, the largest bricks, the reserve, the image writer's need, the least budget that
    /// works and the in-core size, when the budget is below the reserve plus the largest bricks or
    /// below what writing the image takes after the render.
    static StatusOr<RenderMemoryPlan> Make(const RenderMemoryInputs& inputs);

    /// Sets the brick budget, the queue memory and the process budget of `pager`, and the wave size
    /// of `settings`: the settings the render, its summary and its checks then read.
    void Apply(PagerOptions* pager, RenderSettings* settings) const;

    /// "--memory 620.0 MiB: 300.1 MiB for bricks (...), 319.9 MiB (335439052 bytes) reserved[, of
    /// which 12.0 MiB for the texture cache]", for the log.
    std::string Describe() const;
    /// "waves of 614400 camera paths (--wave-paths); their rays beyond 32.0 MiB of queues spill to
    /// disk" when the plan chose the wave size, else empty.
    std::string DescribeWaves() const;

    uint64_t memory_bytes() const { return memory_bytes_; }
    /// What the resident bricks may take (PagerOptions::brick_budget_bytes).
    uint64_t brick_budget_bytes() const { return brick_budget_bytes_; }
    /// Ray queues kept in memory before spilling (PagerOptions::queue_memory_bytes; 0: no spill).
    uint64_t queue_memory_bytes() const { return queue_memory_bytes_; }
    /// Camera paths (or photons) per wave.
    uint32_t wave_paths() const { return wave_paths_; }
    /// Whether the plan chose wave_paths rather than keeping the settings'.
    bool chose_wave_paths() const { return chose_wave_paths_; }
    /// Everything but bricks while rendering; of which the next three.
    uint64_t reserve_bytes() const { return reserve_bytes_; }
    uint64_t texture_cache_bytes() const { return texture_cache_bytes_; }
    uint64_t load_scratch_bytes() const { return load_scratch_bytes_; }
    uint64_t checkpoint_bytes() const { return checkpoint_bytes_; }
    /// The process, the film and OpenImageIO when the image is written, bricks freed.
    uint64_t image_writer_bytes() const { return image_writer_bytes_; }
    /// The least --memory that works for these inputs.
    uint64_t minimum_bytes() const { return minimum_bytes_; }

  private:
    RenderMemoryPlan() = default;

    uint64_t memory_bytes_ = 0;
    uint64_t brick_budget_bytes_ = 0;
    uint64_t queue_memory_bytes_ = 0;
    uint32_t wave_paths_ = 0;
    bool chose_wave_paths_ = false;
    uint64_t reserve_bytes_ = 0;
    uint64_t texture_cache_bytes_ = 0;
    uint64_t load_scratch_bytes_ = 0;
    uint64_t checkpoint_bytes_ = 0;
    uint64_t image_writer_bytes_ = 0;
    uint64_t minimum_bytes_ = 0;
    uint32_t brick_count_ = 0;
    uint64_t all_bricks_bytes_ = 0;
};

}  // namespace nave::render
