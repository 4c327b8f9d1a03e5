#pragma once
// Photon mode: stochastic progressive photon mapping (transport/visible_points.h) on the ray
// streams. Each round is an iteration: a camera pass (VisiblePointPass, stopping at the visible
// points) and then a photon pass (photons from PhotonEmitters, deposited at the visible points),
// each drained to the last ray before the next starts.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "src/core/status.h"
#include "src/render/integrators/integrator.h"
#include "src/render/integrators/visible_point_pass.h"
#include "src/render/transport/light_sampling.h"
#include "src/render/transport/photon_emitters.h"
#include "src/render/transport/visible_points.h"

namespace nave::render {

/// Runs photon mode, and traces its photons: the RayProcessor of the photon pass. ProcessBatch is
/// thread-safe; the rest is called from the render's thread.
class SppmIntegrator final : public Integrator, public RayProcessor {
  public:
    /// Photon mode for `scene` into `film`, rays scheduled by `scheduler` (all must outlive the
    /// integrator): gathers the emitters and the windows in one pass over the bricks. Errors: no
    /// emitter, portal settings without portals, a brick that cannot be pinned.
    static StatusOr<std::unique_ptr<SppmIntegrator>> Create(const RenderScene& scene, Film* film,
                                                            StreamScheduler& scheduler);

    int rounds_wanted() const override { return scene_.settings.iterations; }
    ProgressUnits progress_units() const override { return {"photon mapping", "iterations", 1}; }
    void set_progress(ProgressBar* progress) override { progress_ = progress; }
    Status Restore(const RenderSession& session) override;
    /// One iteration: the camera pass, then the photon pass.
    StatusOr<int> RenderRounds(int done, bool boundaries) override;
    /// From the two halves of the film's samples and of the photons (visible_points.h).
    double NoiseEstimate(int iterations) const override;
    std::array<double, 2> HalfLuminances(uint32_t pixel, int iterations) const override;
    /// The visible points' density sums into the first process's (the guides and windows are
    /// shared after every iteration).
    Status ShareState(RankGroup& ranks) override;
    void Save(Checkpoint* checkpoint) const override;
    /// Adds the photon estimate of the `done` iterations to the film.
    Status Finish(int done, RenderStats* stats) override;

    void ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                      std::span<const RayRecord> rays, RayOutbox& out) override;

  private:
    SppmIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                   std::unique_ptr<PhotonEmitters> emitters, std::unique_ptr<LightSampler> lights,
                   std::unique_ptr<PathGuide> gather_guide);
    /// Shades a photon hit: deposit at visible points, continue by BSDF sampling.
    bool ShadePhoton(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit);
    /// Flies photon `r` over [t0, t1] of its ray in brick `b` (pinned as `brick`; kNoBrick and
    /// null outside every brick) through the scene's medium, as camera paths fly
    /// (CameraPaths::FlyTo): true if it gets to t1, false if it scattered on the way and went on
    /// from there (or ended). True at once without a medium.
    bool FlyPhoton(RayRecord& r, float t0, float t1, uint32_t b, const ResidentBrick* brick,
                   RayOutbox& out);
    /// A sky photon at its first diffuse hit `h`: teaches the sky's next-event estimation which
    /// window lights that region (SkyWindows).
    void LearnWindow(const RayRecord& r, const SurfaceHit& h);
    /// In a distributed render, after a photon pass: what every process learned (the photons'
    /// deposits, the windows' records, the gather guide's credits), in every process.
    /// Collective.
    Status ShareLearning(RankGroup& ranks);
    static constexpr uint32_t kLearnWindowEvery = 4;

    const RenderScene& scene_;
    Film* film_;
    StreamScheduler& scheduler_;
    std::unique_ptr<PhotonEmitters> emitters_;
    std::unique_ptr<LightSampler> lights_;  // shares the emitters' portals
    std::unique_ptr<VisiblePoints> visible_;
    // With final gathering: where the indirect light at a first diffuse vertex comes from,
    // learned from the photons that bounced before arriving (null otherwise).
    std::unique_ptr<PathGuide> gather_guide_;
    VisiblePointPass camera_pass_;
    // Per photon of the pass (the first PhotonEmitters::learned_photons()), the luminance it
    // brought to the visible points, for the emitters to learn from: in fixed point, 2^32 units
    // to a typical photon's power (deposit_to_fixed_ units per unit of luminance).
    std::vector<uint64_t> deposited_;
    const double deposit_to_fixed_;
    uint32_t iteration_ = 0;
    const bool sky_direct_photons_;  // render.sky_direct = "photons"
    const bool final_gather_;        // render.final_gather
    ProgressBar* progress_ = nullptr;
};

}  // namespace nave::render
