#include "src/render/integrator.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <memory>

#include "src/core/check.h"
#include "src/core/memory.h"
#include "src/render/light_sampling.h"
#include "src/render/path_integrator.h"
#include "src/render/sppm_integrator.h"
#include "src/render/stream_scheduler.h"

namespace nave::render {
namespace {

/// Runs the mode of scene.settings on `scheduler` and fills `stats`.
Status Render(const RenderScene& scene, Film* film, RenderStats* stats, StreamScheduler& scheduler,
              const SessionOptions* options) {
    RenderSession session(options, film);
    const auto start = std::chrono::steady_clock::now();
    const BrickSourceStats before = scene.source->stats();
    if (scene.settings.mode == RenderSettings::Mode::kPath) {
        NAVE_ASSIGN_OR_RETURN(std::unique_ptr<LightSampler> lights,
                              LightSampler::Create(scene, scheduler, nullptr));
        PathIntegrator paths(scene, film, scheduler, *lights);
        NAVE_RETURN_IF_ERROR(paths.Run(stats, &session));
    } else {
        SppmIntegrator sppm(scene, film, scheduler);
        NAVE_RETURN_IF_ERROR(sppm.Run(stats, &session));
    }
    stats->wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    scheduler.FillStats(before, stats);
    stats->peak_rss_bytes = PeakRssBytes();
    return Status::Ok();
}

}  // namespace

uint32_t PickFullestBrick(const std::vector<size_t>& waiting, const BrickSource&) {
    return uint32_t(std::max_element(waiting.begin(), waiting.end()) - waiting.begin());
}

Status RenderStreams(const RenderScene& scene, Film* film, RenderStats* stats, BrickPicker picker,
                     const PagerOptions* paging, const SessionOptions* session) {
    NAVE_CHECK(film->width() == scene.camera->width() && film->height() == scene.camera->height());
    int threads = scene.settings.threads > 0 ? scene.settings.threads
                                             : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    Status status;
    arena.execute([&] {
        StreamScheduler scheduler(*scene.source, std::move(picker), scene.settings.wave_paths);
        // In-core too, the pager loads bricks in the background while the workers trace.
        status = scheduler.EnablePaging(paging != nullptr ? *paging : PagerOptions());
        if (status.ok()) status = Render(scene, film, stats, scheduler, session);
    });
    return status;
}

}  // namespace nave::render
