#include "src/render/integrators/render_streams.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "src/core/check.h"
#include "src/core/image_error.h"
#include "src/core/memory.h"
#include "src/core/progress.h"
#include "src/render/integrators/integrator.h"
#include "src/render/integrators/stopping_rule.h"
#include "src/render/stream/stream_scheduler.h"

namespace nave::render {
namespace {

/// The image's noise after `done` rounds when every process traced a part of it: the halves'
/// luminances summed over the processes (2 doubles a pixel, held for the sum). Collective.
StatusOr<double> NoiseOverRanks(const Integrator& integrator, int done, size_t pixels,
                                RankGroup& ranks) {
    if (done < 2) return std::nan("");  // the same in every process: no sum needed
    std::vector<double> halves(2 * pixels);
    for (size_t p = 0; p < pixels; ++p) {
        const std::array<double, 2> h = integrator.HalfLuminances(uint32_t(p), done);
        halves[2 * p] = h[0];
        halves[2 * p + 1] = h[1];
    }
    NAVE_RETURN_IF_ERROR(ranks.SumEverywhere(std::span<double>(halves)));
    return HalvesRelMse(pixels, [&](size_t p) {
        return std::array<double, 2>{halves[2 * p], halves[2 * p + 1]};
    });
}

/// Whether a distributed render stops after `done` rounds: the whole image's noise against the
/// target, and each process's clock against the time limit; the processes stop together as soon
/// as one of them says so (their clocks differ a little). Collective.
StatusOr<bool> StopEverywhere(const Integrator& integrator, int done, size_t pixels,
                              RankGroup& ranks, StoppingRule& stop) {
    NAVE_ASSIGN_OR_RETURN(const double noise, NoiseOverRanks(integrator, done, pixels, ranks));
    uint64_t votes = stop.ShouldStop([&] { return noise; }) ? 1 : 0;
    NAVE_RETURN_IF_ERROR(ranks.SumEverywhere(std::span<uint64_t>(&votes, 1)));
    return votes > 0;
}

/// Renders rounds of `integrator` until it has all it asks for, the stopping rule of `settings`
/// ends the render or the session ends this run, then has it complete the film and fill `stats`:
/// the part every mode shares (resume, progress, the stopping rule, checkpoints).
Status RenderRounds(const RenderSettings& settings, Integrator& integrator, RenderSession& session,
                    Film* film, RayExchange& exchange, RankGroup* ranks, RenderStats* stats) {
    const int start = session.start();
    NAVE_RETURN_IF_ERROR(session.RestoreFilm());
    if (session.resume() != nullptr) NAVE_RETURN_IF_ERROR(integrator.Restore(session));
    session.ReleaseResumed();
    const int wanted = integrator.rounds_wanted();
    const ProgressUnits units = integrator.progress_units();
    ProgressBar progress(std::string(units.task),
                         units.per_round * uint64_t(std::max(wanted, start)),
                         std::string(units.unit));
    progress.Add(units.per_round * uint64_t(start));
    integrator.set_progress(&progress);
    // In a distributed render paths end in every process: the others report theirs to this bar.
    exchange.ShareProgress(&progress);
    struct Unset {
        Integrator& integrator;
        RayExchange& exchange;
        ~Unset() {
            integrator.set_progress(nullptr);
            exchange.ShareProgress(nullptr);
        }
    } unset{integrator, exchange};  // before `progress` goes, whichever way this returns
    StoppingRule stop(settings, &progress, session.elapsed_before_s());
    const bool checks = settings.noise_target > 0 || settings.time_limit_s > 0;
    int done = start;
    while (done < wanted) {
        NAVE_ASSIGN_OR_RETURN(done, integrator.RenderRounds(done, session.active()));
        bool enough = false;
        if (ranks != nullptr && checks) {
            NAVE_ASSIGN_OR_RETURN(
                enough, StopEverywhere(integrator, done, film->pixel_count(), *ranks, stop));
        } else {
            enough = stop.ShouldStop([&] { return integrator.NoiseEstimate(done); });
        }
        bool end_run = false;
        NAVE_RETURN_IF_ERROR(session.AtBoundary(
            done, stop.Elapsed(), enough || done >= wanted,
            [&](RankGroup& group) { return integrator.ShareState(group); },
            [&](Checkpoint* checkpoint) { integrator.Save(checkpoint); }, &end_run));
        if (enough || end_run) break;
    }
    NAVE_RETURN_IF_ERROR(integrator.Finish(done, stats));
    NAVE_RETURN_IF_ERROR(exchange.FinishProgress());
    if (ranks != nullptr) {
        // Each process's film holds the samples it traced: the image is their sum, in every one.
        NAVE_RETURN_IF_ERROR(
            film->CombineSums([&](std::span<double> v) { return ranks->SumEverywhere(v); },
                              [&](std::span<float> v) { return ranks->SumEverywhere(v); },
                              [&](std::span<uint32_t> v) { return ranks->SumEverywhere(v); }));
        stats->noise_relmse = integrator.NoiseEstimate(done);
    }
    progress.Finish();
    return Status::Ok();
}

}  // namespace

Status RenderStreams(const RenderScene& scene, Film* film, RenderStats* stats, BrickPicker picker,
                     const PagerOptions* paging, const SessionOptions* session_options,
                     RankGroup* ranks) {
    NAVE_CHECK(film->width() == scene.camera->width() && film->height() == scene.camera->height());
    int threads = scene.settings.threads > 0 ? scene.settings.threads
                                             : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    Status status;
    arena.execute([&] {
        status = [&]() -> Status {
            // In-core too, the pager loads bricks in the background while the workers trace.
            NAVE_ASSIGN_OR_RETURN(
                std::unique_ptr<StreamScheduler> scheduler,
                StreamScheduler::Create(*scene.source, paging != nullptr ? *paging : PagerOptions(),
                                        std::move(picker), scene.settings.wave_paths, ranks));
            RenderSession session(session_options, film, ranks);
            const auto start = std::chrono::steady_clock::now();
            const BrickSourceStats before = scene.source->stats();
            NAVE_ASSIGN_OR_RETURN(std::unique_ptr<Integrator> integrator,
                                  Integrator::Create(scene, film, *scheduler));
            NAVE_RETURN_IF_ERROR(RenderRounds(scene.settings, *integrator, session, film,
                                              scheduler->exchange(), ranks, stats));
            stats->wall_seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            scheduler->FillStats(before, stats);
            NAVE_RETURN_IF_ERROR(scheduler->SumStatsOverRanks(stats));
            stats->peak_rss_bytes = PeakRssBytes();
            return Status::Ok();
        }();
    });
    return status;
}

}  // namespace nave::render
