#pragma once
// Path mode: unidirectional path tracing on the ray streams (docs/render.md, "Light transport"),
// with next-event estimation and MIS at every non-specular vertex and path guiding
// (render.path_guiding). A round is a pass of one sample per pixel; small images share a wave
// between several passes.

#include <cstdint>
#include <memory>

#include "src/core/status.h"
#include "src/render/integrators/camera_paths.h"
#include "src/render/integrators/integrator.h"
#include "src/render/transport/light_sampling.h"
#include "src/render/transport/path_guide.h"

namespace nave::render {

class PathIntegrator final : public Integrator, public CameraPaths {
  public:
    /// Path mode for `scene` into `film`, rays scheduled by `scheduler` (all must outlive the
    /// integrator). Errors: sky portal sampling without portals (LightSampler::Create).
    static StatusOr<std::unique_ptr<PathIntegrator>> Create(const RenderScene& scene, Film* film,
                                                            StreamScheduler& scheduler);

    int rounds_wanted() const override { return scene_.settings.spp; }
    ProgressUnits progress_units() const override;
    void set_progress(ProgressBar* progress) override { set_path_progress(progress); }
    Status Restore(const RenderSession& session) override;
    /// The passes after the first `passes`: one, or with small images several in one wave.
    StatusOr<int> RenderRounds(int passes, bool boundaries) override;
    double NoiseEstimate(int passes) const override;
    std::array<double, 2> HalfLuminances(uint32_t pixel, int passes) const override;
    /// The path guide's credits, summed over the processes (PathGuide::ShareCredits).
    Status ShareState(RankGroup& ranks) override;
    void Save(Checkpoint* checkpoint) const override;
    Status Finish(int passes, RenderStats* stats) override;

  private:
    PathIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                   std::unique_ptr<LightSampler> lights, std::unique_ptr<PathGuide> guide);
    /// The radiance the guide's fixed point is scaled to (PathGuide).
    static double GuideRadianceScale(const RenderScene& scene);
    /// Path tracing's vertex: next-event estimation weighted against the (guided) BSDF, crediting
    /// the guide, then the continuation.
    bool ScatterAt(RayRecord& r, uint32_t b, const ResidentBrick& brick, const SurfaceHit& h,
                   bool last, RayOutbox& out) override;

    // What CameraPaths samples and credits, owned here.
    std::unique_ptr<LightSampler> owned_lights_;
    std::unique_ptr<PathGuide> owned_guide_;  // with render.path_guiding
};

}  // namespace nave::render
