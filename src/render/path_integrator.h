#pragma once
// Unidirectional path tracing on the ray streams (docs/render.md, "Light transport"): camera rays,
// shading of path hits with next-event estimation and MIS, shadow rays through thin glass, escapes
// to the sky and the sun. Path mode runs it for every pass; photon mode's camera pass uses it to
// find the visible points.

#include <cstdint>
#include <memory>
#include <span>

#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/render/brick_source.h"
#include "src/render/film.h"
#include "src/render/integrator.h"
#include "src/render/light_sampling.h"
#include "src/render/path_guide.h"
#include "src/render/ray.h"
#include "src/render/render_session.h"
#include "src/render/scene.h"
#include "src/render/stream_scheduler.h"

namespace nave {
class ProgressBar;
}

namespace nave::render {

class VisiblePoints;

/// Traces camera paths and their shadow rays: the RayProcessor of path mode and of photon mode's
/// camera pass. ProcessBatch is thread-safe; the rest is called from the render's thread.
class PathIntegrator final : public RayProcessor {
  public:
    /// Paths of `scene` into `film`, their rays scheduled by `scheduler`, lights sampled by
    /// `lights` (all must outlive the integrator). `visible_points`: photon mode, where paths stop
    /// at their first diffuse vertex and leave their visible point there; null in path mode.
    PathIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                   const LightSampler& lights, VisiblePoints* visible_points = nullptr);

    /// Path mode: renders scene.settings.spp passes (fewer once time_limit_s runs out or the
    /// noise estimate reaches noise_target) in waves of wave_paths, and fills samples_per_pixel,
    /// camera_paths and noise_relmse of `stats`. `session` (may be null: one run from the start)
    /// resumes from a checkpoint, writes checkpoints and may end the run early. Errors: a
    /// checkpoint that does not match this scene, a failed checkpoint write.
    Status Run(RenderStats* stats, RenderSession* session = nullptr);
    /// Queues the camera rays of pixels [first, last) for sample `sample` (wavelengths per path, or
    /// the iteration's when `lambda` is given), spilling queues beyond their cap as it goes.
    /// Errors: a failed spill.
    Status GenerateCameraRays(uint64_t first, uint64_t last, uint32_t sample,
                              const SampledWavelengths* lambda);
    /// Keys the random numbers of the paths generated and traced from now on to SPPM iteration
    /// `iteration` (path mode: 0).
    void set_iteration(uint32_t iteration) { iteration_ = iteration; }

    void ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                      std::span<const RayRecord> rays, RayOutbox& out) override;

  private:
    /// The radiance the guide's fixed point is scaled to (PathGuide).
    double GuideRadianceScale() const;
    /// The image's estimated relMSE after `passes` passes, from the film's two halves.
    double NoiseEstimate(int passes) const;
    void GenerateCameraChunk(uint64_t first, uint64_t last, uint32_t sample,
                             const SampledWavelengths* lambda);
    void ProcessRay(RayRecord r, uint32_t b, const ResidentBrick& brick, RayOutbox& out);
    /// The half of the samples (Film::SampleHalf) path `r` belongs to: its pass in path mode, the
    /// iteration in photon mode.
    int Half(const RayRecord& r) const { return Film::SampleHalf(r.sample + iteration_); }
    /// Shades a camera-path hit: emission, next-event estimation, continuation. Returns false if
    /// the path ends.
    bool ShadePath(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit,
                   RayOutbox& out);
    /// A path leaving the model: the sky and the sun it finds, weighted against their next-event
    /// estimation.
    void Escape(const RayRecord& r);
    /// A shadow ray that reached its light: its contribution to the film and, for a guided path,
    /// to the guide.
    void AddShadowContribution(const RayRecord& r);
    /// Traces a shadow ray's segment in `brick` up to t1: false if something opaque blocks it. Thin
    /// glass (windows) lets it through, scaled by the pane's transmittance at that angle: panes do
    /// not bend rays.
    bool ShadowThroughBrick(RayRecord& r, const ResidentBrick& brick, float t1, RayCounts& c) const;
    /// Starts path or shadow ray `r` made in brick `b` (pinned as `brick`; kNoBrick and null for
    /// camera rays): queued at the first brick along it, or ended if it misses the model; a shadow
    /// ray that starts in `b` is traced at once.
    void Spawn(RayRecord r, uint32_t b, const ResidentBrick* brick, RayOutbox& out);

    const RenderScene& scene_;
    Film* film_;
    StreamScheduler& scheduler_;
    const LightSampler& lights_;
    VisiblePoints* visible_points_;     // photon mode
    std::unique_ptr<PathGuide> guide_;  // path mode with render.path_guiding
    uint32_t iteration_ = 0;
    const bool has_thin_glass_;
    ProgressBar* progress_ = nullptr;  // during Run: counts the paths that end
};

}  // namespace nave::render
