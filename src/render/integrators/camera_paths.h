#pragma once
// Camera paths on the ray streams, as path mode and photon mode's camera pass share them: camera
// rays, the walk of a path through the bricks, emission found by a path, next-event estimation at
// its vertices with shadow rays through thin glass, escapes to the sky and the sun, and the
// continuation by BSDF sampling. What a path does at a vertex is its integrator's (ScatterAt): path
// tracing goes on (PathIntegrator), photon mode's camera pass stops at the first diffuse vertex
// and leaves its visible point there (VisiblePointPass).

#include <cstdint>
#include <span>

#include "src/core/status.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/film/film.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/surface_hit.h"
#include "src/render/stream/ray.h"
#include "src/render/stream/stream_scheduler.h"
#include "src/render/transport/light_sampling.h"
#include "src/render/transport/path_guide.h"
#include "src/render/transport/rng.h"

namespace nave {
class ProgressBar;
}

namespace nave::render {

/// Traces camera paths and their shadow rays. ProcessBatch is thread-safe; the rest is called from
/// the render's thread.
class CameraPaths : public RayProcessor {
  public:
    /// Queues the camera rays of pixels [first, last) for sample `sample`, spilling queues beyond
    /// their cap as it goes. Errors: a failed spill.
    Status GenerateCameraRays(uint64_t first, uint64_t last, uint32_t sample);
    /// Keys the random numbers of the paths generated and traced from now on to SPPM iteration
    /// `iteration` (path mode: 0).
    void set_iteration(uint32_t iteration) { iteration_ = iteration; }
    /// Counts every path that ends on `progress` (null: none); must outlive the paths' tracing.
    void set_path_progress(ProgressBar* progress) { progress_ = progress; }

    void ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                      std::span<const RayRecord> rays, RayOutbox& out) override;

  protected:
    /// Paths of `scene` into `film`, their rays scheduled by `scheduler`, lights sampled by
    /// `lights`, guided and crediting `guide` (null: unguided); all must outlive the paths.
    CameraPaths(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                const LightSampler& lights, PathGuide* guide);

    /// What the path `r` does at its vertex `h` (brick `b`, pinned as `brick`) after the emission
    /// there is counted; `last`: the path reached its last scattering (it may still pass through
    /// thin glass). Scatters `r` in place and returns whether it goes on.
    virtual bool ScatterAt(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                           const SurfaceHit& h, bool last, RayOutbox& out) = 0;

    /// Next-event estimation at vertex `h` of path `r` with BSDF `bsdf`, seen from `wo`: a shadow
    /// ray toward every light and, with `sky`, toward the sky, each weighted against
    /// `mis_against` (null: full weight) and crediting guide cell `credit` with `credit_scale`
    /// (PathGuide::kNoCredit: none).
    void EstimateDirect(const RayRecord& r, uint32_t b, const ResidentBrick& brick,
                        const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo,
                        const VertexRng& rng, const GuidedBsdf* mis_against, bool sky,
                        uint32_t credit, float credit_scale, RayOutbox& out);
    /// Continues path `r` from vertex `h` by sampling `continuation`; `side` is the side of the
    /// surface the path sees (PathGuide::SideOf). Russian roulette past the second bounce. Returns
    /// whether the path goes on.
    bool Continue(RayRecord& r, const SurfaceHit& h, const GuidedBsdf& continuation,
                  const VertexRng& rng, int side, bool last) const;

    /// The half of the samples (Film::SampleHalf) path `r` belongs to: its pass in path mode, the
    /// iteration in photon mode.
    int Half(const RayRecord& r) const { return Film::SampleHalf(r.sample + iteration_); }
    uint32_t iteration() const { return iteration_; }

    const RenderScene& scene_;
    Film* film_;
    StreamScheduler& scheduler_;

  private:
    void GenerateCameraChunk(uint64_t first, uint64_t last, uint32_t sample);
    void ProcessRay(RayRecord r, uint32_t b, const ResidentBrick& brick, RayOutbox& out);
    /// Shades a camera-path hit: absorption, AOVs and emission, then ScatterAt. Returns false if
    /// the path ends.
    bool ShadePath(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit,
                   RayOutbox& out);
    /// A path leaving the model: the sky and the sun it finds, weighted against their next-event
    /// estimation.
    void Escape(const RayRecord& r);
    /// Path ray `r` at its end without a surface: it leaves the model (Escape), weighted for the
    /// medium it crossed.
    void LeaveModel(RayRecord r);
    /// The density's integral at which path ray `r` scatters in the scene's medium (FlightDepth,
    /// from its vertex's random numbers, so known again in every brick the ray crosses).
    float PathFlightDepth(const RayRecord& r) const;
    /// Flies path ray `r` over [t0, t1] of its ray while it is processed in brick `b` (pinned as
    /// `brick`; kNoBrick and null outside every brick) through the medium there: true if it gets
    /// to t1 (its flight_depth grown by what it crossed), false if it scattered on the way and
    /// went on from there (ScatterInMedium). True at once without a medium.
    bool FlyTo(RayRecord& r, float t0, float t1, uint32_t b, const ResidentBrick* brick,
               RayOutbox& out);
    /// Adds to path `r`'s pixel the light `medium` emits over [t0, t1] of its ray through `field`,
    /// its flight having entered t0 at `depth0` of the density's integral (EmissionAlong).
    void AddMediumEmission(const RayRecord& r, const Medium& medium, const DensityField& field,
                           float depth0, float t0, float t1);
    /// Path `r` scatters in the medium at t = `t` of its ray, where its flight reached `depth` (its
    /// PathFlightDepth): next-event estimation of the lights and the sky through the phase
    /// function, then the path goes on in a direction sampled from it. `b` and `brick` as for
    /// FlyTo.
    void ScatterInMedium(RayRecord r, float t, float depth, uint32_t b, const ResidentBrick* brick,
                         RayOutbox& out);
    /// Whether light found by path `r` is a caustic that photon mode's caustic points count
    /// already: a gathering path whose every bounce past its first diffuse vertex was specular
    /// (visible_points.h). Path mode never gathers.
    static bool CausticFromPhotons(const RayRecord& r) {
        return (r.flags & kGathering) && (r.flags & kSpecularChain);
    }
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

    const LightSampler& lights_;
    PathGuide* guide_;
    uint32_t iteration_ = 0;
    const bool has_thin_glass_;
    ProgressBar* progress_ = nullptr;
};

}  // namespace nave::render
