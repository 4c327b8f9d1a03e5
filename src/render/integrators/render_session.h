#pragma once
// A render as one run of several (docs/render.md, "Checkpoints"): it may continue from a
// checkpoint, write checkpoints between its passes (path mode) or iterations (photon mode), and end
// early, after a number of them or on request (SIGINT / SIGTERM caught by the command), leaving a
// checkpoint to continue from. The integrators call RenderSession at their boundaries.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>

#include "src/core/status.h"
#include "src/render/film/checkpoint.h"
#include "src/render/film/film.h"

namespace nave::render {

class RankGroup;

/// What the command asks of the run.
struct SessionOptions {
    /// Continue from this state (already checked against `identity`); null: from the start. The
    /// run drops its sections once restored (they can be as large as the film and the guide).
    Checkpoint* resume = nullptr;
    /// The file `resume` was read from, for messages.
    std::string resume_name;
    /// Write checkpoints here; empty: none.
    std::filesystem::path checkpoint_path;
    /// At least this long between two checkpoints (seconds; 0: after every pass or iteration).
    /// The last pass or iteration of the run always writes one.
    double checkpoint_every_s = 600;
    /// End this run after this many passes or iterations of its own (0: no limit).
    int stop_after = 0;
    /// When set (by a signal handler), the run ends at its next boundary. May be null.
    const std::atomic<bool>* stop_requested = nullptr;
    /// What the checkpoints written belong to (mode included).
    CheckpointIdentity identity;

    /// Whether anything here asks for boundaries between passes: every pass then ends with all its
    /// rays traced, so that the image does not depend on where checkpoints were written.
    bool active() const { return resume != nullptr || !checkpoint_path.empty() || stop_after > 0; }
};

/// The most memory writing a checkpoint takes beside the render (its sections, built one after
/// the other and held until written): the film's state and the path guide's (path mode with
/// render.path_guiding) or photon mode's per-pixel sums and photon guides. `aov`: the film has
/// AOV buffers.
uint64_t CheckpointMemoryBytes(const RenderSettings& settings, int width, int height, bool aov);

/// One run's checkpointing, used by the integrators from the render's thread.
class RenderSession {
  public:
    /// `options` null: a render in one run (no resume, no checkpoints, never stops early).
    /// `ranks`: the processes of a distributed render (null: one process), which agree on every
    /// boundary's decisions; the first of them writes the checkpoints and restores the film from
    /// one (docs/distributed.md, "Checkpoints").
    RenderSession(const SessionOptions* options, Film* film, RankGroup* ranks = nullptr);

    bool active() const { return options_ != nullptr && options_->active(); }
    /// The checkpoint this run continues from, or null.
    const Checkpoint* resume() const { return options_ != nullptr ? options_->resume : nullptr; }
    /// Passes or iterations done before this run, and the seconds they took.
    int start() const { return start_; }
    double elapsed_before_s() const { return elapsed_before_s_; }
    /// Restores the film from the checkpoint (nothing without one; in a distributed render, the
    /// first process's only: the others' films start empty). Errors: a film section of another
    /// size or truncated.
    Status RestoreFilm();
    /// The file resumed from, for messages.
    const std::string& resume_name() const { return options_->resume_name; }
    /// The bytes of section `name` of the checkpoint resumed from (there must be one).
    StatusOr<std::string_view> Section(const std::string& name) const;
    /// Frees the checkpoint's sections once everything is restored from them.
    void ReleaseResumed();

    /// Called after `done` passes or iterations in all, `elapsed_s` seconds of rendering in all;
    /// `last`: the render ends here anyway. Writes a checkpoint when one is due (or this run ends
    /// here) with the film and the sections `save` adds; sets `*stop` when this run ends here.
    /// In a distributed render it is collective: the processes end the run or write a checkpoint
    /// when one of them asks to (a signal, its clock); then the films are summed into the first
    /// process's (the others' are cleared), `share` makes the integrator's state every process's,
    /// and the first process writes.
    Status AtBoundary(int done, double elapsed_s, bool last,
                      const std::function<Status(RankGroup&)>& share,
                      const std::function<void(Checkpoint*)>& save, bool* stop);

  private:
    const SessionOptions* options_;
    Film* film_;
    RankGroup* ranks_;
    int start_ = 0;
    double elapsed_before_s_ = 0;
    std::chrono::steady_clock::time_point last_write_;
};

}  // namespace nave::render
