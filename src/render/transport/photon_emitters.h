#pragma once
// Where SPPM's photons come from: every emitter of the scene (sun, directional, point and spot
// lights, the sky, emissive triangles) chosen in proportion to a rough power, and where photons
// from distant sources start (a disc covering the model, or with render.photon_target = "portals"
// mostly the windows).

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "src/core/byte_stream.h"
#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/scene/lights/triangle_light.h"
#include "src/render/scene/scene.h"
#include "src/render/stream/stream_scheduler.h"
#include "src/render/transport/light_sampling.h"
#include "src/render/transport/photon_guide.h"
#include "src/render/transport/photon_portals.h"

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
    /// threads; each photon carries its own wavelengths. `footprint`: the width of each photon's
    /// cone (ray.h), the iteration's gather radius: a photon stands for the light within it. A
    /// photon that meets no brick goes to `meets_no_brick` if given (in a medium it may still
    /// scatter toward one), else it carries nothing.
    void EmitPhotons(uint64_t first, uint64_t last, uint32_t iteration, float footprint,
                     StreamScheduler& scheduler,
                     const std::function<void(RayRecord&, RayOutbox&)>& meets_no_brick = {});
    /// After a photon pass: learns where the sun's photons are worth starting (photon_guide.h) from
    /// deposited[k], the luminance photon k brought to the visible points in fixed point
    /// (`fixed_per_luminance` units to one), for the first learned_photons() photons of the pass.
    void Learn(std::span<const uint64_t> deposited, double fixed_per_luminance);
    /// Appends what the guides learned to `out`, for a checkpoint.
    void SaveState(ByteWriter* out) const;
    /// Restores what SaveState saved, as after the Learn calls that learned it. Errors: DataLoss
    /// for other guides or truncated bytes.
    Status LoadState(ByteReader* in);
    /// How many photons of a pass Learn looks at (the first ones): a cap on its memory.
    uint64_t learned_photons() const { return photon_cells_.size(); }
    /// The bytes learning takes with `photons_per_iteration`: per learned photon its start cell
    /// here and what it deposited, in fixed point (SppmIntegrator).
    static uint64_t LearningBytes(uint64_t photons_per_iteration) {
        return std::min(photons_per_iteration, kMaxLearnedPhotons) *
               (sizeof(uint32_t) + sizeof(uint64_t));
    }

    /// The windows photons are aimed through: null unless render.photon_target = "portals" found
    /// portal triangles.
    const SkyPortals* sky_portals() const { return sky_portals_.get(); }
    /// The model's bounding sphere, on which photons from distant sources start.
    const Vec3f& scene_center() const { return scene_center_; }
    float scene_radius() const { return scene_radius_; }
    /// The power of a typical photon (the emitters' total selection weight: photons are emitted in
    /// proportion to power, so each carries about this much, in the units of Light::Power).
    double typical_photon_power() const { return total_power_; }

  private:
    struct Emitter {
        const Light* light = nullptr;           // the scene's light or sky, or a triangle's
        const DistantLight* distant = nullptr;  // light->distant(): photons start facing it
        uint8_t flags = 0;                      // RayFlags of its photons
        int portal = -1;                        // distant: index in portals_ when aiming at windows
        int guide = -1;                         // distant: index in guides_
    };
    explicit PhotonEmitters(const RenderScene& scene) : scene_(scene) {}

    // Aimed at windows, this share of the photons from distant sources (sun, directional, sky) goes
    // through the portals, the rest through the disc covering the model; each photon's power is
    // divided by the mixture of both densities (a one-sample balance heuristic, Veach 1997 §9.2).
    // Unbiased for all the light: what enters elsewhere (gaps, doors) or is reflected into a
    // window from outside (reveals, buttresses, roofs) comes with the disc's photons. In the
    // abbey that is more than half of the light inside.
    static constexpr float kPortalPhotonShare = 0.75f;
    // The sky's photons likewise. A larger share measures less noise from two seeds at equal time
    // (480x320, 30 s: relMSE 0.21 at 0.5, 0.14 at 0.75, 0.11 at 0.9, 0.097 at 0.97) but only
    // because the light reflected into the windows from outside then comes in rare photons of great
    // power that most renders miss: at 0.95 the abbey agreement test's photon image was 2.6 %
    // darker than path tracing's (AbbeyAgreementSlow).
    static constexpr float kSkyPortalPhotonShare = 0.75f;
    // Once a guide has learned (photon_guide.h), the sun's photons are drawn from it with this
    // share, the portals' share is scaled to the rest, and the disc keeps what remains.
    static constexpr float kGuidePhotonShare = 0.6f;
    // Cells per side of a guide's grid, and the most photons of a pass it learns from.
    static constexpr int kGuideCells = 128;
    static constexpr uint64_t kMaxLearnedPhotons = uint64_t(1) << 22;
    /// Starts photon `r` of distant light `e` (sun or directional) toward -to: on the portals, the
    /// guide or the disc, with the mixture's area density; returns 1 / density (m^2) and records
    /// the photon's start cell for Learn.
    float StartDistantPhoton(const Emitter& e, const Vec3f& to, const VertexRng& rng, RayRecord* r);
    /// Fills the emitters and their CDF (Build).
    Status Gather(StreamScheduler& scheduler);

    const RenderScene& scene_;
    std::vector<TriangleLight> triangle_lights_;  // the emissive triangles
    std::vector<Emitter> emitters_;
    std::vector<double> emitter_cdf_;  // normalised, emitters_.size() + 1 entries
    std::vector<PortalProjection> portals_;
    std::vector<PhotonGuide> guides_;
    // Per photon of a pass (the first kMaxLearnedPhotons): guide index << 16 | start cell, or
    // kNoGuideCell.
    std::vector<uint32_t> photon_cells_;
    static constexpr uint32_t kNoGuideCell = 0xffffffffu;
    // Photons aimed at the portals: every portal triangle in one Embree scene, to count the portals
    // a photon's line crosses (the balance-heuristic weight), and the area CDF to pick
    // start points.
    std::unique_ptr<SkyPortals> sky_portals_;
    Vec3f scene_center_;
    float scene_radius_ = 1;
    double total_power_ = 0;
};

}  // namespace nave::render
