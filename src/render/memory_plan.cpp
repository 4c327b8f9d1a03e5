#include "src/render/memory_plan.h"

#include <algorithm>

#include "src/core/memory.h"
#include "src/render/film.h"
#include "src/render/render_session.h"

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

RenderMemoryInputs RenderMemoryInputs::Measure(const BrickSource& source,
                                               const PagerOptions& pager) {
    RenderMemoryInputs inputs;
    inputs.pager = pager;
    inputs.brick_count = source.brick_count();
    inputs.bricks = MinimumBrickBudget(source, pager.prefetch);
    // One decode at a time under a budget: the largest load's scratch is the most beside bricks.
    for (uint32_t b = 0; b < source.brick_count(); ++b) {
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
    plan.queue_memory_bytes_ = in.pager.queue_memory_bytes == PagerOptions::kAutoQueueMemory
                                   ? QueueMemoryBytes(in.memory_bytes)
                                   : in.pager.queue_memory_bytes;
    // Writing a checkpoint holds the film's and the guide's state beside them.
    plan.checkpoint_bytes_ =
        in.checkpoints ? CheckpointMemoryBytes(in.settings, in.width, in.height, in.aov) : 0;
    RenderSettings settings = in.settings;
    auto reserve_for = [&](const RenderSettings& s) {
        return RenderReserveBytes(s, in.width, in.height, in.brick_count, in.pager.wave_overlap,
                                  in.process_bytes, plan.queue_memory_bytes_) +
               plan.texture_cache_bytes_ + plan.load_scratch_bytes_ + plan.checkpoint_bytes_;
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
    plan.image_writer_bytes_ = in.process_bytes +
                               (in.image_library_loaded ? 0 : kImageWriterBytes) +
                               Film::MemoryBytes(in.width, in.height);
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
    pager->process_memory_bytes = memory_bytes_;
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
