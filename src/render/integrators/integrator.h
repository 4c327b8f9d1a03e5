#pragma once
// The integrators: one interface for the light transport of a render mode, one factory by mode.
// A render is a number of rounds (path mode: passes of one sample per pixel; photon mode: SPPM
// iterations) that RenderStreams drives: it restores a checkpoint, shows progress, asks the
// stopping rule after every round and writes checkpoints between rounds. An integrator renders
// rounds, estimates its noise, saves and restores its own state and completes the film.
//
// A new integrator is a new file with a class implementing Integrator and a case in
// Integrator::Create; it traces its rays as a RayProcessor on the scheduler's streams.

#include <memory>
#include <string_view>

#include "src/core/status.h"
#include "src/render/film/checkpoint.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_session.h"
#include "src/render/integrators/render_stats.h"
#include "src/render/scene/scene.h"
#include "src/render/stream/stream_scheduler.h"

namespace nave {
class ProgressBar;
}

namespace nave::render {

/// What the progress bar of a render counts.
struct ProgressUnits {
    std::string_view task;   ///< "render"
    std::string_view unit;   ///< "paths"
    uint64_t per_round = 1;  ///< units in one round
};

/// The light transport of one render mode. Called from the render's thread; the rays it traces go
/// through the scheduler's workers.
class Integrator {
  public:
    virtual ~Integrator() = default;

    /// The integrator of scene.settings.mode, rendering into `film` on `scheduler`'s streams (all
    /// must outlive it). Errors: what its mode needs and the scene lacks (photon mode without a
    /// light; portal settings without portals), a brick that cannot be pinned while preparing.
    static StatusOr<std::unique_ptr<Integrator>> Create(const RenderScene& scene, Film* film,
                                                        StreamScheduler& scheduler);

    /// Rounds the settings ask for (spp or iterations).
    virtual int rounds_wanted() const = 0;
    /// What the progress bar counts, and the bar to count on while rendering (null: none).
    virtual ProgressUnits progress_units() const = 0;
    virtual void set_progress(ProgressBar* progress) = 0;
    /// Restores the state it saved (Save) from the checkpoint `session` resumes from; the film is
    /// restored by the driver. Errors: sections of another scene, truncated sections.
    virtual Status Restore(const RenderSession& session) = 0;
    /// Renders the rounds after the first `done` (one, or a few that share waves) and returns how
    /// many are done then. `boundaries`: every round must end with all its rays traced (a session
    /// that may write checkpoints or stop early). Errors: a brick that cannot be pinned, a failed
    /// spill.
    virtual StatusOr<int> RenderRounds(int done, bool boundaries) = 0;
    /// The image's estimated relMSE after `done` rounds (NaN with fewer than two): HalvesRelMse of
    /// HalfLuminances over the pixels.
    virtual double NoiseEstimate(int done) const = 0;
    /// The luminance of the two halves of `pixel`'s samples after `done` rounds (NaN for a half
    /// with none yet): what NoiseEstimate measures. In a distributed render each process's are the
    /// part of the image it traced, and their sums over the processes are the whole image's.
    virtual std::array<double, 2> HalfLuminances(uint32_t pixel, int done) const = 0;
    /// In a distributed render, before a checkpoint: makes the state Save writes (what its guides
    /// learned) every process's together, in every process. Collective.
    virtual Status ShareState(RankGroup& ranks) = 0;
    /// Adds its state (guides, visible points) to a checkpoint.
    virtual void Save(Checkpoint* checkpoint) const = 0;
    /// After the last round: traces what is still in flight, completes the film for `done` rounds
    /// and fills the integrator's fields of `stats`.
    virtual Status Finish(int done, RenderStats* stats) = 0;
};

}  // namespace nave::render
