#include "src/render/integrators/render_session.h"

#include "src/core/byte_stream.h"
#include "src/core/log.h"
#include "src/render/stream/ray_exchange.h"
#include "src/render/transport/path_guide.h"
#include "src/render/transport/sky_windows.h"

namespace nave::render {

uint64_t CheckpointMemoryBytes(const RenderSettings& settings, int width, int height, bool aov) {
    const uint64_t pixels = uint64_t(width) * uint64_t(height);
    uint64_t state = 0;
    if (settings.mode == RenderSettings::Mode::kPath) {
        if (settings.path_guiding)
            state = PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGuideMaxCells,
                                           GuideRounds::kDoublingPasses);
    } else {
        // Four doubles per pixel, and a few photon guides of 128 x 128 doubles; the gather guide
        // and the sky windows' sums (key, sum, count) when they learn.
        state = pixels * 4 * sizeof(double) + (uint64_t(1) << 20);
        if (settings.final_gather)
            state += PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGatherGuideMaxCells);
        if (settings.LearnsSkyWindows()) state += SkyWindows::kMaxPairs * 20;
    }
    return Film::StateBytes(width, height, aov) + state;
}

RenderSession::RenderSession(const SessionOptions* options, Film* film, RankGroup* ranks)
    : options_(options), film_(film), ranks_(ranks), last_write_(std::chrono::steady_clock::now()) {
    if (resume() != nullptr) {
        start_ = int(resume()->done);
        elapsed_before_s_ = resume()->elapsed_seconds;
    }
}

void RenderSession::ReleaseResumed() {
    if (resume() != nullptr) options_->resume->sections.clear();
}

StatusOr<std::string_view> RenderSession::Section(const std::string& name) const {
    NAVE_CHECK(resume() != nullptr) << "section " << name << " without a checkpoint";
    return resume()->Section(name, options_->resume_name);
}

Status RenderSession::RestoreFilm() {
    // The checkpoint's film holds every process's samples: one process restores it, so that the
    // sum of the films at the end counts them once.
    if (resume() == nullptr || (ranks_ != nullptr && ranks_->rank() != 0)) return Status::Ok();
    NAVE_ASSIGN_OR_RETURN(std::string_view bytes, Section("film"));
    ByteReader r(bytes, options_->resume_name + " section film");
    return film_->LoadState(&r);
}

Status RenderSession::AtBoundary(int done, double elapsed_s, bool last,
                                 const std::function<Status(RankGroup&)>& share,
                                 const std::function<void(Checkpoint*)>& save, bool* stop) {
    *stop = false;
    if (options_ == nullptr) return Status::Ok();
    const SessionOptions& o = *options_;
    *stop = (o.stop_after > 0 && done - start() >= o.stop_after) ||
            (o.stop_requested != nullptr && o.stop_requested->load(std::memory_order_relaxed));
    if (o.checkpoint_path.empty() && ranks_ == nullptr) return Status::Ok();
    const auto now = std::chrono::steady_clock::now();
    bool due = !o.checkpoint_path.empty() &&
               std::chrono::duration<double>(now - last_write_).count() >= o.checkpoint_every_s;
    if (ranks_ != nullptr) {
        // Votes are sums over the processes, which wait for rays in flight to be traced first:
        // only rounds of an active session end with all their rays traced.
        if (!active()) return Status::Ok();
        // One vote each for ending the run and for a checkpoint: a signal may reach one process
        // only, and their clocks differ a little.
        uint64_t votes[2] = {*stop ? 1u : 0u, due ? 1u : 0u};
        NAVE_RETURN_IF_ERROR(ranks_->SumEverywhere(std::span<uint64_t>(votes)));
        *stop = votes[0] > 0;
        due = votes[1] > 0;
    }
    if (o.checkpoint_path.empty() || (!due && !last && !*stop)) return Status::Ok();
    if (ranks_ != nullptr) {
        // Every process's samples into the first one's film: the others go on from empty films,
        // and the films' sum at the end is the same.
        NAVE_RETURN_IF_ERROR(
            film_->CombineSums([&](std::span<double> v) { return ranks_->SumEverywhere(v); },
                               [&](std::span<float> v) { return ranks_->SumEverywhere(v); },
                               [&](std::span<uint32_t> v) { return ranks_->SumEverywhere(v); }));
        if (ranks_->rank() != 0) film_->Clear();
        NAVE_RETURN_IF_ERROR(share(*ranks_));
        last_write_ = std::chrono::steady_clock::now();
        if (ranks_->rank() != 0) return Status::Ok();
    }
    Checkpoint checkpoint;
    checkpoint.identity = o.identity;
    checkpoint.done = uint32_t(done);
    checkpoint.elapsed_seconds = elapsed_s;
    ByteWriter film;
    film_->SaveState(&film);
    checkpoint.sections["film"] = film.Take();
    save(&checkpoint);
    NAVE_RETURN_IF_ERROR(
        WriteCheckpoint(o.checkpoint_path, checkpoint).WithContext("--checkpoint"));
    log::Debug("checkpoint after {} {}: {}", done, o.identity.mode == 0 ? "passes" : "iterations",
               o.checkpoint_path.string());
    last_write_ = std::chrono::steady_clock::now();
    return Status::Ok();
}

}  // namespace nave::render
