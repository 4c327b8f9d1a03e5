#include "src/render/stream/memory_plan.h"

#include <algorithm>

#include "src/core/memory.h"

namespace nave::render {
namespace {

// ", of which X for the texture cache" when there is one: the refusal and the plan's line alike.
std::string TextureCacheClause(uint64_t texture_cache_bytes) {
    return texture_cache_bytes > 0 ? fmt::format(", of which {} for the texture cache",
                                                 FormatBytes(texture_cache_bytes))
                                   : std::string();
}

}  // namespace

uint64_t TextureCacheCapBytes(const TextureConfig& textures, std::optional<uint64_t> memory_bytes) {
    if (!memory_bytes) return textures.cache_bytes;
    return uint64_t(double(*memory_bytes) * textures.memory_share);
}

uint64_t TextureCacheEnoughBytes(uint64_t opened_pixel_bytes) {
    return 2 * opened_pixel_bytes + (uint64_t(4) << 20);
}

uint64_t QueueMemoryBytes(const PagerOptions& paging) {
    if (paging.queue_memory_bytes != PagerOptions::kAutoQueueMemory) {
        return paging.queue_memory_bytes;
    }
    return std::max<uint64_t>(uint64_t(32) << 20, paging.memory_bytes / 32);
}

uint32_t WavePathsUnderPaging(const RenderSettings& settings, int width, int height) {
    if (settings.wave_paths_chosen || settings.mode != RenderSettings::Mode::kPath) {
        return settings.wave_paths;
    }
    const uint64_t paths = uint64_t(width) * uint64_t(height) * uint64_t(std::max(1, settings.spp));
    return uint32_t(std::max<uint64_t>(settings.wave_paths, std::min(paths, kMaxPagedWavePaths)));
}

size_t MaxBatchRays(uint64_t queue_memory_bytes) {
    constexpr size_t kMaxBatch = size_t(1) << 18;
    if (queue_memory_bytes == 0) return kMaxBatch;
    // The batch itself, and up to two records sent on per ray (a continuation and a shadow ray)
    // pushed before the next spill.
    return std::clamp<size_t>(size_t(queue_memory_bytes / (3 * sizeof(RayRecord))), 4096,
                              kMaxBatch);
}

uint64_t RenderReserveBytes(const RenderMemoryInputs& in, const RenderSettings& settings,
                            uint64_t queue_memory_bytes) {
    const uint64_t pixels = uint64_t(in.width) * uint64_t(in.height);
    // The process without bricks, and per brick its queue, slot, statistics and occupancy grid.
    const uint64_t process =
        in.process_bytes + kRenderGrowthBytes + uint64_t(in.brick_count) * 256 + in.occupancy_bytes;
    // Ray queues: the camera paths of a wave each with a shadow ray in flight, and the batch taken
    // from a queue (at most one record per ray in flight).
    const uint64_t per_pass =
        settings.mode == RenderSettings::Mode::kPath ? uint64_t(std::max(1, settings.spp)) : 1;
    uint64_t in_flight = std::min<uint64_t>(settings.wave_paths, pixels * per_pass);
    if (settings.mode == RenderSettings::Mode::kPhoton) {
        in_flight = std::max<uint64_t>(
            in_flight, std::min<uint64_t>(settings.wave_paths, settings.photons_per_iteration));
    }
    // Under paging the next wave is generated while wave_overlap of a wave is still waiting.
    in_flight += uint64_t(double(std::min<uint64_t>(settings.wave_paths, in_flight)) *
                          std::clamp(in.pager.wave_overlap, 0.0, 1.0));
    // Two records per path in flight: measured peaks are 0.85 (the demo in-core, 84 MiB for waves
    // of 1 M paths) to 1.1 (the detail-110 abbey paged at 2G, 124 MiB for 1.09 M paths) records per
    // path, with the queues' partly filled blocks.
    uint64_t queues = 2 * in_flight * sizeof(RayRecord);
    // Spilling keeps the queues under their cap between batches; a batch adds itself and what its
    // rays send on.
    if (queue_memory_bytes > 0) {
        queues = std::min(
            queues, queue_memory_bytes + 3 * MaxBatchRays(queue_memory_bytes) * sizeof(RayRecord));
    }
    return process + in.state.film + queues + in.state.transport;
}

RenderMemoryInputs RenderMemoryInputs::Measure(const BrickSource& source,
                                               const PagerOptions& pager) {
    RenderMemoryInputs inputs;
    inputs.pager = pager;
    inputs.brick_count = source.slot_count();
    inputs.bricks = MinimumBrickBudget(source, pager.prefetch);
    // Grids known from the start are held all along; with skip_air on, made as bricks load.
    if (source.occupancy_known() || pager.skip_air == PagerOptions::SkipAir::kOn)
        inputs.occupancy_bytes =
            uint64_t(source.brick_count()) * store::OccupancyGrid::kMemoryBytes;
    // One decode at a time under a budget: the largest load's scratch is the most beside bricks.
    for (uint32_t b = 0; b < source.slot_count(); ++b) {
        inputs.load_scratch_bytes = std::max(inputs.load_scratch_bytes, source.LoadScratchBytes(b));
    }
    inputs.process_bytes = CurrentRssBytes();
    return inputs;
}

StatusOr<RenderMemoryPlan> RenderMemoryPlan::Make(const RenderMemoryInputs& in) {
    RenderMemoryPlan plan;
    plan.memory_bytes_ = in.memory_bytes;
    plan.brick_count_ = in.brick_count;
    plan.all_bricks_bytes_ = in.bricks.total_bytes;
    plan.texture_cache_bytes_ = in.texture_cache_bytes;
    plan.load_scratch_bytes_ = in.load_scratch_bytes;
    // Queues beyond a small share of the budget spill to disk.
    PagerOptions paging = in.pager;
    paging.memory_bytes = in.memory_bytes;
    plan.queue_memory_bytes_ = QueueMemoryBytes(paging);
    // Writing a checkpoint holds the film's and the guide's state beside them.
    plan.checkpoint_bytes_ = in.state.checkpoint;
    RenderSettings settings = in.settings;
    auto reserve_for = [&](const RenderSettings& s) {
        return RenderReserveBytes(in, s, plan.queue_memory_bytes_) + plan.texture_cache_bytes_ +
               plan.load_scratch_bytes_ + plan.checkpoint_bytes_;
    };
    plan.reserve_bytes_ = reserve_for(settings);
    // When the bricks will not all fit, one wave for the whole image unless the user chose
    // (WavePathsUnderPaging): its camera rays spill to disk as they are generated.
    if (plan.queue_memory_bytes_ > 0 &&
        in.memory_bytes < plan.reserve_bytes_ + in.bricks.total_bytes) {
        const uint32_t wave = WavePathsUnderPaging(settings, in.width, in.height);
        if (wave != settings.wave_paths) {
            settings.wave_paths = wave;
            plan.reserve_bytes_ = reserve_for(settings);
            plan.chose_wave_paths_ = true;
        }
    }
    plan.wave_paths_ = settings.wave_paths;
    // The image is written after the bricks are freed, but OpenImageIO must fit then (unless the
    // texture cache loaded it already: the process's size counts it then).
    plan.image_writer_bytes_ =
        in.process_bytes + (in.image_library_loaded ? 0 : kImageWriterBytes) + in.state.film;
    plan.minimum_bytes_ =
        std::max(plan.reserve_bytes_ + in.bricks.min_bytes, plan.image_writer_bytes_);
    if (in.memory_bytes < plan.minimum_bytes_) {
        return ResourceExhaustedError(
            "--memory {} ({} bytes) is too small for this model: {}, the reserve for the film, "
            "ray queues and process is {} ({} bytes){}, and writing the image afterwards takes {} "
            "({} bytes, OpenImageIO included): at least {} ({} bytes) is needed (all {} bricks "
            "resident at once take {}, {} bytes)",
            in.memory_text, in.memory_bytes, in.bricks.DescribeLargest(in.pager.prefetch),
            FormatBytes(plan.reserve_bytes_), plan.reserve_bytes_,
            TextureCacheClause(plan.texture_cache_bytes_), FormatBytes(plan.image_writer_bytes_),
            plan.image_writer_bytes_, FormatBytes(plan.minimum_bytes_), plan.minimum_bytes_,
            in.brick_count, FormatBytes(in.bricks.total_bytes), in.bricks.total_bytes);
    }
    plan.brick_budget_bytes_ = in.memory_bytes - plan.reserve_bytes_;
    // The one budget that would read as in-core (kUnlimitedBrickBudget) is a byte short of it.
    if (plan.brick_budget_bytes_ == kUnlimitedBrickBudget) --plan.brick_budget_bytes_;
    return plan;
}

void RenderMemoryPlan::Apply(PagerOptions* pager, RenderSettings* settings) const {
    pager->brick_budget_bytes = brick_budget_bytes_;
    pager->queue_memory_bytes = queue_memory_bytes_;
    pager->memory_bytes = memory_bytes_;
    settings->wave_paths = wave_paths_;
}

std::string RenderMemoryPlan::Describe() const {
    return fmt::format(
        "--memory {}: {} for bricks ({} for all {} bricks at once, {} bytes), {} ({} bytes) "
        "reserved{}",
        FormatBytes(memory_bytes_), FormatBytes(brick_budget_bytes_),
        FormatBytes(all_bricks_bytes_), brick_count_, all_bricks_bytes_,
        FormatBytes(reserve_bytes_), reserve_bytes_, TextureCacheClause(texture_cache_bytes_));
}

std::string RenderMemoryPlan::DescribeWaves() const {
    if (!chose_wave_paths_) return std::string();
    return fmt::format(
        "waves of {} camera paths (--wave-paths); their rays beyond {} of queues spill to disk",
        wave_paths_, FormatBytes(queue_memory_bytes_));
}

}  // namespace nave::render
