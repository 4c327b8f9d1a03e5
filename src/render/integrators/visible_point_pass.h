#pragma once
// Photon mode's camera pass (sppm_integrator.h): camera paths through specular and glossy chains
// to their first diffuse vertex, where they leave their visible point for the photons of the
// iteration; direct light there, and light found along the chains, is next-event estimated as in
// path mode.

#include <cstdint>

#include "src/render/integrators/camera_paths.h"
#include "src/render/transport/visible_points.h"

namespace nave::render {

class VisiblePointPass final : public CameraPaths {
  public:
    /// Visible points of `scene`'s camera paths into `visible_points`, the light the paths find
    /// into `film`; rays scheduled by `scheduler`, lights sampled by `lights`; with final
    /// gathering the bounce guided by `gather_guide` where it guides (null: by the BSDF alone).
    /// All must outlive the pass.
    VisiblePointPass(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                     const LightSampler& lights, VisiblePoints* visible_points,
                     const PathGuide* gather_guide = nullptr);

  private:
    /// At a diffuse vertex the path stops: next-event estimation at full weight (no continuation
    /// will look for the lights), the visible point left there. With render.final_gather it
    /// bounces once more first (next-event estimation weighed against that bounce) and leaves
    /// its visible point at the next diffuse vertex, with no estimation there. Elsewhere it goes
    /// on as a path.
    bool ScatterAt(RayRecord& r, uint32_t b, const ResidentBrick& brick, const SurfaceHit& h,
                   bool last, RayOutbox& out) override;

    VisiblePoints* visible_points_;
    const bool sky_from_photons_;  // render.sky_direct = "photons"
    const bool final_gather_;      // render.final_gather
    const PathGuide* gather_guide_;
};

}  // namespace nave::render
