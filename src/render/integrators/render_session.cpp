#include "src/render/integrators/render_session.h"

#include "src/core/byte_stream.h"
#include "src/core/log.h"
#include "src/render/transport/path_guide.h"
#include "src/render/transport/sky_windows.h"

namespace nave::render {

uint64_t CheckpointMemoryBytes(const RenderSettings& settings, int width, int height, bool aov) {
    const uint64_t pixels = uint64_t(width) * uint64_t(height);
    uint64_t state = 0;
    if (settings.mode == RenderSettings::Mode::kPath) {
        if (settings.path_guiding)
            state = PathGuide::MemoryBytes(kGuideCoarseCellsLongAxis, kGuideMaxCells);
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

RenderSession::RenderSession(const SessionOptions* options, Film* film)
    : options_(options), film_(film), last_write_(std::chrono::steady_clock::now()) {
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
    if (resume() == nullptr) return Status::Ok();
    NAVE_ASSIGN_OR_RETURN(std::string_view bytes, Section("film"));
    ByteReader r(bytes, options_->resume_name + " section film");
    return film_->LoadState(&r);
}

Status RenderSession::AtBoundary(int done, double elapsed_s, bool last,
                                 const std::function<void(Checkpoint*)>& save, bool* stop) {
    *stop = false;
    if (options_ == nullptr) return Status::Ok();
    const SessionOptions& o = *options_;
    *stop = (o.stop_after > 0 && done - start() >= o.stop_after) ||
            (o.stop_requested != nullptr && o.stop_requested->load(std::memory_order_relaxed));
    if (o.checkpoint_path.empty()) return Status::Ok();
    const auto now = std::chrono::steady_clock::now();
    const bool due =
        std::chrono::duration<double>(now - last_write_).count() >= o.checkpoint_every_s;
    if (!due && !last && !*stop) return Status::Ok();
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
