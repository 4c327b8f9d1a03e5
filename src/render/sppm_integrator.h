#pragma once
// Photon mode: stochastic progressive photon mapping (sppm.h) on the ray streams. Each iteration
// traces a camera pass (PathIntegrator, stopping at the visible points) and then a photon pass
// (photons from PhotonEmitters, deposited at the visible points), each drained to the last ray
// before the next starts.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "src/core/status.h"
#include "src/render/brick_source.h"
#include "src/render/film.h"
#include "src/render/integrator.h"
#include "src/render/photon_emission.h"
#include "src/render/ray.h"
#include "src/render/render_session.h"
#include "src/render/scene.h"
#include "src/render/sppm.h"
#include "src/render/stream_scheduler.h"

namespace nave::render {

/// Runs photon mode, and traces its photons: the RayProcessor of the photon pass. ProcessBatch is
/// thread-safe; Run is called from the render's thread.
class SppmIntegrator final : public RayProcessor {
  public:
    /// Photon mode for `scene` into `film`, rays scheduled by `scheduler` (all must outlive the
    /// integrator).
    SppmIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler);

    /// Renders scene.settings.iterations SPPM iterations (fewer once time_limit_s runs out or the
    /// noise estimate reaches noise_target) and adds
    /// the photon estimate to the film; fills iterations, samples_per_pixel, camera_paths and
    /// photons of `stats`. Errors: no emitter, portal settings without portals, a brick that cannot
    /// be pinned. `session` (may be null: one run from the start) resumes from a checkpoint, writes
    /// checkpoints and may end the run early; errors: a checkpoint that does not match this scene,
    /// a failed checkpoint write.
    Status Run(RenderStats* stats, RenderSession* session = nullptr);

    void ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                      std::span<const RayRecord> rays, RayOutbox& out) override;

  private:
    /// The image's estimated relMSE after `iterations` iterations, from the two halves of the
    /// film's samples and of the photons (sppm.h).
    double NoiseEstimate(int iterations) const;
    /// Shades a photon hit: deposit at visible points, continue by BSDF sampling.
    bool ShadePhoton(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit);

    const RenderScene& scene_;
    Film* film_;
    StreamScheduler& scheduler_;
    std::unique_ptr<VisiblePoints> visible_;
    // Per photon of the pass (the first PhotonEmitters::learned_photons()), the luminance it
    // brought to the visible points, for the emitters to learn from.
    std::vector<float> deposited_;
    uint32_t iteration_ = 0;
    const bool sky_direct_photons_;  // render.sky_direct = "photons"
};

}  // namespace nave::render
