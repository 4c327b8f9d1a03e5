#pragma once
// Next-event estimation: sampling the lights and the sky from a surface vertex, with shadow rays
// that carry the contribution, and the sky portals (windows) that sky samples and sky photons are
// aimed through.

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/scene/materials/bxdf.h"
#include "src/render/scene/media/henyey_greenstein.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/surface_hit.h"
#include "src/render/stream/ray.h"
#include "src/render/transport/path_guide.h"
#include "src/render/transport/rng.h"
#include "src/render/transport/sky_windows.h"

namespace nave::render {

class RankGroup;
class StreamScheduler;

/// The triangles of portal materials (windows) as one small Embree scene, to count the portals a
/// line crosses, with the area CDF to pick points on them. Immutable once built: thread-safe.
class SkyPortals {
  public:
    /// Builds the portal scene and area CDF from `triangles` (not empty) on the Embree device of
    /// `source`.
    static StatusOr<std::unique_ptr<SkyPortals>> Build(const BrickSource& source,
                                                       std::vector<std::array<Vec3f, 3>> triangles);

    /// A point uniform on the portals' total area from `u_triangle` (picks a triangle by area) and
    /// `u`; its triangle in `triangle` if given.
    Vec3f SamplePoint(double u_triangle, Point2f u, size_t* triangle = nullptr) const;
    /// Calls `visit(hit)` for each portal triangle the ray o + t d crosses with t in [0, t_max] (at
    /// most 64), front to back; returns how many.
    template <typename Visit>
    int ForEachCrossing(const Vec3f& o, const Vec3f& d, float t_max, Visit visit) const {
        int count = 0;
        BrickHit hit;
        for (float t0 = 0; count < 64 && scene_->Intersect(o, d, t0, t_max, &hit); ++count) {
            visit(hit);
            t0 = hit.t + 1e-6f * (1.f + hit.t);
        }
        return count;
    }
    /// Total area of the portal triangles (m^2).
    double area() const { return area_; }
    /// Portal triangle `i` (the index SamplePoint gives, and BrickHit::triangle of a crossing).
    const std::array<Vec3f, 3>& triangle(size_t i) const { return triangles_[i]; }
    size_t triangle_count() const { return triangles_.size(); }
    /// The area of portal triangle `i` (m^2).
    double TriangleArea(size_t i) const { return (area_cdf_[i + 1] - area_cdf_[i]) * area_; }
    /// The first portal triangle the ray o + t d crosses (t > 0), or nothing.
    std::optional<BrickHit> FirstCrossing(const Vec3f& o, const Vec3f& d) const {
        BrickHit hit;
        if (!scene_->Intersect(o, d, 0, std::numeric_limits<float>::infinity(), &hit))
            return std::nullopt;
        return hit;
    }

  private:
    SkyPortals() = default;
    std::unique_ptr<ResidentBrick> scene_;
    std::vector<std::array<Vec3f, 3>> triangles_;
    std::vector<double> area_cdf_;  // normalised, triangles_.size() + 1 entries
    double area_ = 0;
};

/// Next-event estimation of the scene's lights and sky. Immutable once created: thread-safe.
class LightSampler {
  public:
    /// The light sampler of `scene`. With render.sky_sampling = "portals", sky samples are mostly
    /// aimed at the windows: in path mode their triangles are gathered here (one pass over the
    /// bricks through `scheduler`; an error if no material is a portal or the model has no portal
    /// triangle); in photon mode the sampler shares `photon_portals`, the photon emitters' portals
    /// (PhotonEmitters::sky_portals, which must outlive the sampler), and samples the sky uniformly
    /// with a warning when there are none, and learns the windows from the sky's photons of
    /// luminance about `photon_power` (sky_windows()).
    static StatusOr<std::unique_ptr<LightSampler>> Create(const RenderScene& scene,
                                                          StreamScheduler& scheduler,
                                                          const SkyPortals* photon_portals,
                                                          double photon_power = 0);

    /// Next-event estimation of `light` (index `index` in scene.lights) at hit `h` with BSDF
    /// `bsdf`, seen from `wo`, for the path of `r`: the shadow ray toward the light carrying its
    /// contribution (added if nothing occludes it), or nothing when it contributes nothing.
    /// `continuation`: how the path goes on from here (its BSDF, maybe guided), to weigh the light
    /// sample against (power heuristic) where the continuation can hit the light; null: no
    /// continuation will look for it, full weight.
    std::optional<RayRecord> SampleLight(const Light& light, int index, const SurfaceHit& h,
                                         const Bsdf& bsdf, const Vec3f& wo, const RayRecord& r,
                                         const VertexRng& rng,
                                         const GuidedBsdf* continuation) const;
    /// Next-event estimation of the sky: a uniform direction on the sphere, or with
    /// render.sky_sampling = "portals" mostly a direction toward a point on a window (SkyPdf):
    /// where the sky's photons taught the vertex's region its windows (SkyWindows), mostly one
    /// of those. Weighted against `continuation` as SampleLight does. Returns the shadow ray as
    /// SampleLight does.
    std::optional<RayRecord> SampleSky(const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo,
                                       const RayRecord& r, const VertexRng& rng,
                                       const GuidedBsdf* continuation) const;
    /// Next-event estimation of `light` from point `p` in a medium whose phase function is
    /// `phase`, for the path of `r` arriving there along r.dir: the shadow ray (its contribution
    /// before the medium's transmittance, which CameraPaths::Spawn applies), weighted against
    /// sampling the phase function (power heuristic), or nothing.
    std::optional<RayRecord> SampleLightInMedium(const Light& light, int index, const Vec3f& p,
                                                 const HenyeyGreenstein& phase, const RayRecord& r,
                                                 const VertexRng& rng) const;
    /// Next-event estimation of the sky from point `p` in a medium, as SampleSky picks directions
    /// (SkyPdf with side 0), weighted against the phase function as SampleLightInMedium is.
    std::optional<RayRecord> SampleSkyInMedium(const Vec3f& p, const HenyeyGreenstein& phase,
                                               const RayRecord& r, const VertexRng& rng) const;
    /// The solid-angle pdf with which SampleSky picks direction `w` at point `p` on a surface of
    /// side `side` (PathGuide::SideOf, turned toward the path): the mixture of uniform
    /// directions, portal sampling by area, whose pdf sums d² / (|cos θ| A_portals) over every
    /// portal triangle the ray from p crosses (each crossing could have been the sampled point;
    /// Veach 1997 §9.2 area-to-solid-angle conversion), and the region's learned windows, which
    /// sums d² / |cos θ| times the crossed triangle's SkyWindows::AreaDensity.
    float SkyPdf(const Vec3f& p, int side, const Vec3f& w) const;
    /// Photon mode with portals: the windows the sky's photons and shadow rays teach (null
    /// otherwise). Record into it while photons are traced; SkyWindows::Update between passes,
    /// never while the sampler samples.
    SkyWindows* sky_windows() const { return windows_.get(); }
    /// A shadow ray of SampleSky (kSkyShadow) that reached the sky records, for its vertex's
    /// region, the window it crossed and its estimate of that window's light there: the
    /// contribution without the path's throughput, the BSDF or the MIS weight, that is the sky's
    /// radiance x the panes' transmittance x |cos θ| / the pdf of its direction. Nothing without
    /// sky_windows(). Thread-safe.
    void LearnFromSkyShadow(const RayRecord& shadow) const;
    /// The portal triangles of every process of a distributed render, in the order one process
    /// finds them, from this process's `triangles` and the brick of each. Collective.
    static StatusOr<std::vector<std::array<Vec3f, 3>>> GatherPortals(
        RankGroup& ranks, const std::vector<std::array<Vec3f, 3>>& triangles,
        const std::vector<uint32_t>& bricks);

  private:
    /// A direction toward the sky from `p` on a surface of side `side`, drawn as SkyPdf says, or
    /// nothing.
    std::optional<Vec3f> SampleSkyDirection(const Vec3f& p, int side, const VertexRng& rng) const;
    /// The shadow ray of path `r` from its medium vertex `p` toward `wi`, up to `t_max`, without
    /// its contribution.
    static RayRecord ShadowFromMedium(const RayRecord& r, const Vec3f& p, const Vec3f& wi,
                                      float t_max);

    explicit LightSampler(const RenderScene& scene) : scene_(scene) {}
    /// The order of a shadow ray's estimate of a window's light in `scene` (SkyWindows' scale).
    static double TypicalWindowLight(const RenderScene& scene);

    // Sky next-event estimation toward the portals: this share of the samples, the rest uniform
    // (which keeps light that enters elsewhere, and vertices outside, sampled).
    static constexpr float kPortalSkyShare = 0.75f;
    // Where a region learned its windows: this share from them, and of the rest kPortalSkyShare
    // by area, the remainder uniform.
    static constexpr float kLearnedSkyShare = 0.7f;
    const RenderScene& scene_;
    std::unique_ptr<SkyWindows> windows_;
    std::unique_ptr<SkyPortals> own_portals_;  // path mode
    const SkyPortals* portals_ = nullptr;      // null: the sky is sampled uniformly
};

}  // namespace nave::render
