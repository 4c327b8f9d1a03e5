#pragma once
// Where SPPM's photons come from: every emitter of the scene (sun, directional, point and spot
// lights, the sky, emissive triangles) chosen in proportion to a rough power, and where photons
// from distant sources start (a disc covering the model, or with render.photon_target = "portals"
// mostly the windows).

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/spectrum.h"
#include "core/status.h"
#include "core/vecmath.h"
#include "render/light_sampling.h"
#include "render/photon_portals.h"
#include "render/scene.h"

namespace nave::render {

class StreamScheduler;

/// The photon emitters of a scene and their selection weights. Immutable once built: thread-safe.
class PhotonEmitters {
  public:
    /// Gathers the emitters of `scene`: its lights and sky, and the triangles of emissive materials
    /// (with the portal triangles for render.photon_target = "portals") in one pass over the bricks
    /// through `scheduler`. Errors: no emitter with power, or portals wanted and no material is a
    /// portal.
    static StatusOr<std::unique_ptr<PhotonEmitters>> Build(const RenderScene& scene,
                                                           StreamScheduler& scheduler);

    /// Queues photons [first, last) of SPPM iteration `iteration` through `scheduler`, on all
    /// threads; each photon carries its own wavelengths.
    void EmitPhotons(uint64_t first, uint64_t last, uint32_t iteration,
                     StreamScheduler& scheduler) const;

    /// The windows sky photons are aimed through: null unless the scene has a sky and
    /// render.photon_target = "portals" found portal triangles.
    const SkyPortals* sky_portals() const { return sky_portals_.get(); }
    /// The model's bounding sphere, on which photons from distant sources start.
    const Vec3f& scene_center() const { return scene_center_; }
    float scene_radius() const { return scene_radius_; }

  private:
    struct Emitter {
        enum class Kind { kLight, kSky, kTriangle };
        Kind kind = Kind::kLight;
        const Light* light = nullptr;
        Vec3f v0, v1, v2, n;  // kTriangle
        float area = 0;
        const SurfaceMaterial* material = nullptr;  // kTriangle: what it emits
        std::array<std::array<float, 2>, 3> uv{};   // kTriangle: texture coordinates of v0, v1, v2
        bool has_uv = false;
        int portal = -1;  // kLight (sun, directional): index in portals_ when aiming at windows
    };
    explicit PhotonEmitters(const RenderScene& scene) : scene_(scene) {}

    // Aimed at windows, this share of the photons from distant sources (sun, directional, sky) goes
    // through the portals, the rest through the disc covering the model; each photon's power is
    // divided by the mixture of both densities (a one-sample balance heuristic, Veach 1997 §9.2).
    // Unbiased for all the light: what enters elsewhere (gaps, doors) or is reflected into a
    // window from outside (reveals, buttresses, roofs) comes with the disc's photons. In the
    // abbey that is more than half of the light inside.
    static constexpr float kPortalPhotonShare = 0.75f;
    /// Fills the emitters and their CDF (Build).
    Status Gather(StreamScheduler& scheduler);

    const RenderScene& scene_;
    std::vector<Emitter> emitters_;
    std::vector<double> emitter_cdf_;  // normalised, emitters_.size() + 1 entries
    std::vector<PortalProjection> portals_;
    // Photons aimed at the portals: every portal triangle in one Embree scene, to count the portals
    // a photon's line crosses (the balance-heuristic weight), and the area CDF to pick
    // start points.
    std::unique_ptr<SkyPortals> sky_portals_;
    Vec3f scene_center_;
    float scene_radius_ = 1;
};

}  // namespace nave::render
