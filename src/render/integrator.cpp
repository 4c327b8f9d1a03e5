#include "render/integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

#include "core/log.h"
#include "core/memory.h"
#include "core/progress.h"
#include "core/sampling.h"
#include "render/brick_walk.h"
#include "render/photon_portals.h"
#include "render/ray_queue.h"
#include "render/ray.h"
#include "render/rng.h"
#include "render/sppm.h"

namespace nave::render {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
/// Rays taken from a queue per scheduler step, and rays per task within it.
constexpr size_t kMaxBatch = 1u << 18;
constexpr size_t kChunk = 256;

// Dimensions of a vertex's random numbers (VertexRng::Uniform).
enum Dim : uint32_t {
    kDimPixelX = 0, kDimPixelY, kDimLens0, kDimLens1, kDimLambda,  // camera stream only
    kDimBsdfChoice = 8, kDimBsdf0, kDimBsdf1, kDimRoulette,
    kDimLight0 = 16,  // two per light
};

enum RngStream : uint32_t { kStreamPath = 0, kStreamPhoton = 1, kStreamCamera = 2, kStreamEmit = 3, kStreamLambda = 4 };

/// Moves p off the surface to the side of `w`, so that the spawned ray does not hit the surface it leaves.
/// The offset grows with |p| because float spacing does (2^-23 relative).
Vec3f OffsetOrigin(const Vec3f& p, const Vec3f& ng, const Vec3f& w) {
    float scale = 1e-5f * (1.f + std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}));
    return p + ng * (Dot(ng, w) >= 0 ? scale : -scale);
}

float PowerHeuristic(float a, float b) {
    // Veach 1997, eq. 9.13 with beta = 2.
    if (std::isinf(a)) return 1;
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0 ? a2 / (a2 + b2) : 0;
}

struct LocalCounters {
    uint64_t segments = 0, shadow_segments = 0, moves = 0, rays = 0;
};

/// Rays spawned or moved by one task, flushed to the queues grouped by brick.
using Outbox = std::vector<std::pair<uint32_t, RayRecord>>;

/// The geometry of a hit, from the brick's mesh.
struct SurfaceHit {
    Vec3f p, ng, ns;
    std::array<float, 2> uv{};  ///< [texture] interpolated texture coordinates, when has_uv
    bool has_uv = false;
    TextureFootprint footprint;  ///< texture filter footprint at the hit (with uv on a textured material)
    const SurfaceMaterial* material = nullptr;
};

class Engine {
  public:
    Engine(const RenderScene& scene, Film* film, RenderStats* stats, BrickPicker picker)
        : custom_picker_(bool(picker)),
          picker_(picker ? std::move(picker) : BrickPicker(PickFullestBrick)),
          scene_(scene),
          film_(film),
          stats_(stats),
          tree_(scene.source->tree()),
          queues_(scene.source->brick_count()) {}

    /// Pages bricks under `options` (before Run); refuses an impossible budget.
    Status EnablePaging(const PagerOptions& options) {
        NAVE_ASSIGN_OR_RETURN(pager_, Pager::Create(*scene_.source, options,
                                                    [this](uint32_t b) { return queues_.Waiting(b); }));
        return Status::Ok();
    }
    Status Run();

  private:
    /// Pins brick `b` for a batch or a pass, through the pager when paging; counts the wait.
    StatusOr<BrickHandle> AcquireBrick(uint32_t b) {
        if (pager_) return pager_->Acquire(b);
        const auto start = std::chrono::steady_clock::now();
        StatusOr<BrickHandle> h = scene_.source->Acquire(b);
        stall_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return h;
    }
    Status RunPath();
    Status RunPhoton();
    /// Queues the camera rays of pixels [first, last) for sample `sample` (wavelengths per path, or the
    /// iteration's when `lambda` is given).
    void GenerateCameraRays(uint64_t first, uint64_t last, uint32_t sample, const SampledWavelengths* lambda);
    /// The photon emitters and their selection weights (photon mode).
    Status BuildEmitters();
    /// Queues photons [first, last) of this iteration.
    void EmitPhotons(uint64_t first, uint64_t last, const SampledWavelengths& lambda);

    /// Sets r's segment to the first brick after `from_t` other than `current`; returns it or kNoBrick.
    uint32_t Route(RayRecord& r, float from_t, uint32_t current) const {
        BrickSegment s = NextBrick(tree_, r.origin, r.dir, from_t, r.t_max, current);
        r.t_enter = s.t_enter;
        r.t_exit = s.t_exit;
        return s.brick;
    }
    /// Runs the scheduler until at most `stop_below` rays wait (0: every queue is empty).
    Status Drain(size_t stop_below = 0);
    /// Rays left waiting when the next wave is generated: under paging the next wave joins the tail of the
    /// previous one, whose few scattered rays would otherwise cost a load each (docs/pager.md); in-core,
    /// waves do not overlap.
    size_t WaveOverlap() const {
        return pager_ ? size_t(pager_->options().wave_overlap * double(scene_.settings.wave_paths)) : 0;
    }
    void Flush(Outbox& out, const LocalCounters& c);
    void ProcessRay(RayRecord r, uint32_t b, const ResidentBrick& brick, Outbox& out, LocalCounters& c);
    /// Shades a camera-path hit: emission, next-event estimation, continuation. Returns false if the path ends.
    bool ShadePath(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit, Outbox& out,
                   LocalCounters& c);
    /// Shades a photon hit: deposit at visible points, continue by BSDF sampling.
    bool ShadePhoton(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit);
    void SampleLight(const Light& light, int index, const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo,
                     const RayRecord& r, const VertexRng& rng, bool mis, uint32_t b, const ResidentBrick& brick, Outbox& out,
                     LocalCounters& c);
    void Escape(const RayRecord& r);
    /// Next-event estimation of the sky: a uniform direction on the sphere, or with render.sky_sampling =
    /// "portals" mostly a direction toward a point on a window (SkyPdf), power heuristic with the BSDF.
    void SampleSky(const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo, const RayRecord& r, const VertexRng& rng,
                   bool mis, uint32_t b, const ResidentBrick& brick, Outbox& out, LocalCounters& c);
    /// Traces a shadow ray's segment in `brick` up to t1: false if something opaque blocks it. Thin glass
    /// (windows) lets it through, scaled by the pane's transmittance at that angle: panes do not bend rays.
    bool ShadowThroughBrick(RayRecord& r, const ResidentBrick& brick, float t1, LocalCounters& c) const;
    /// A straight pass through thin glass: the path continues in the same direction, and this is not a
    /// scattering event (depth, MIS state unchanged), as for shadow rays.
    static bool IsPassThrough(const SurfaceMaterial& m, const BsdfSample& bs) {
        return m.thin_glass() != nullptr && bs.IsTransmission();
    }
    void Spawn(RayRecord r, uint32_t b, const ResidentBrick* brick, Outbox& out, LocalCounters& c);
    /// Builds the portal scene and area CDF from the triangles of portal materials.
    Status SetPortals(const std::vector<std::array<Vec3f, 3>>& triangles);
    /// A point uniform on the portals' total area from `u_triangle` (picks a triangle by area) and `u`; its
    /// triangle in `triangle` if given.
    Vec3f SamplePortalPoint(double u_triangle, Point2f u, size_t* triangle = nullptr) const;
    /// Calls `visit(hit)` for each portal triangle the ray o + t d crosses with t in [0, t_max] (at most 64),
    /// front to back; returns how many.
    template <typename Visit>
    int ForEachPortalCrossing(const Vec3f& o, const Vec3f& d, float t_max, Visit visit) const {
        int count = 0;
        BrickHit hit;
        for (float t0 = 0; count < 64 && portal_scene_->Intersect(o, d, t0, t_max, &hit); ++count) {
            visit(hit);
            t0 = hit.t + 1e-6f * (1.f + hit.t);
        }
        return count;
    }
    /// One pass over the bricks (pinned through the pager when paging) calling `visit(mesh, t, b)` for every
    /// triangle t of brick b whose material passes `want`. A triangle stored in several bricks (it crosses
    /// cells) is visited once: in the brick whose cell holds its centroid.
    Status ForEachOwnedTriangle(const std::function<bool(const SurfaceMaterial&)>& want,
                                const std::function<void(const store::BrickMesh&, size_t, uint32_t)>& visit);
    /// With render.sky_sampling = "portals": gathers the portal triangles (one pass over the bricks, unless
    /// the photon emitters gathered them already) so that sky next-event estimation aims at the windows.
    Status BuildSkyPortals();
    /// The solid-angle pdf with which SampleSky picks direction `w` at point `p`: the mixture of uniform
    /// directions and portal sampling, whose pdf sums d² / (|cos θ| A_portals) over every portal triangle the
    /// ray from p crosses (each crossing could have been the sampled point; Veach 1997 §9.2 area-to-solid-angle
    /// conversion).
    float SkyPdf(const Vec3f& p, const Vec3f& w) const;
    /// The hit's geometry; `dir` is the ray's direction (for the texture footprint).
    SurfaceHit MakeSurfaceHit(const ResidentBrick& brick, const BrickHit& hit, const Vec3f& dir) const;
    RngKey Key(const RayRecord& r, uint32_t stream) const {
        return RngKey{scene_.settings.seed, r.pixel, r.sample, r.vertex, iteration_, stream};
    }

    bool custom_picker_;
    BrickPicker picker_;
    double stall_seconds_ = 0;      // in-core
    const RenderScene& scene_;
    Film* film_;
    RenderStats* stats_;
    const store::BrickTree& tree_;
    BrickQueues<RayRecord> queues_;
    // Declared after queues_, so destroyed first: its loader thread reads the queues until joined.
    std::unique_ptr<Pager> pager_;  // null: in-core
    std::atomic<uint64_t> segments_{0}, shadow_segments_{0}, moves_{0}, batches_{0}, rays_{0};
    uint32_t iteration_ = 0;
    bool has_thin_glass_ = std::any_of(scene_.materials.begin(), scene_.materials.end(), [](const SurfaceMaterial& m) {
        return m.thin_glass() != nullptr;
    });
    std::unique_ptr<VisiblePoints> visible_;  // photon mode

    struct Emitter {
        enum class Kind { kLight, kSky, kTriangle };
        Kind kind = Kind::kLight;
        const Light* light = nullptr;
        Vec3f v0, v1, v2, n;  // kTriangle
        float area = 0;
        const SurfaceMaterial* material = nullptr;  // kTriangle: what it emits
        std::array<std::array<float, 2>, 3> uv{};     // kTriangle: texture coordinates of v0, v1, v2
        bool has_uv = false;
        int portal = -1;      // kLight (sun, directional): index in portals_ when aiming at windows
    };
    std::vector<PortalProjection> portals_;
    // Sky photons aimed at the portals: every portal triangle in one Embree scene, to count the portals a
    // photon's line crosses (the balance-heuristic weight), and the area CDF to pick start points.
    std::unique_ptr<ResidentBrick> portal_scene_;
    std::vector<std::array<Vec3f, 3>> portal_triangles_;
    std::vector<double> portal_area_cdf_;
    double portal_area_ = 0;
    // Sky next-event estimation toward the portals: this share of the samples, the rest uniform (which keeps
    // light that enters elsewhere, and vertices outside, sampled).
    bool sky_portals_ = false;
    static constexpr float kPortalSkyShare = 0.75f;
    std::vector<Emitter> emitters_;
    std::vector<double> emitter_cdf_;  // normalised, emitters_.size() + 1 entries
    Vec3f scene_center_;
    float scene_radius_ = 1;
};

SurfaceHit Engine::MakeSurfaceHit(const ResidentBrick& brick, const BrickHit& hit, const Vec3f& dir) const {
    const store::BrickMesh& m = brick.mesh();
    const uint32_t i0 = m.indices[3 * hit.triangle], i1 = m.indices[3 * hit.triangle + 1],
                   i2 = m.indices[3 * hit.triangle + 2];
    const float w0 = 1 - hit.u - hit.v;
    SurfaceHit h;
    // The point from the barycentrics (not o + t d): exact to the triangle's plane whatever t's magnitude.
    h.p = m.positions[i0] * w0 + m.positions[i1] * hit.u + m.positions[i2] * hit.v;
    h.ng = Normalize(Cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]));
    h.ns = h.ng;
    if (m.HasNormals()) {
        Vec3f n = m.normals[i0] * w0 + m.normals[i1] * hit.u + m.normals[i2] * hit.v;
        float len = Length(n);
        if (len > 0) h.ns = n / len;
        if (Dot(h.ns, h.ng) < 0) h.ns = -h.ns;  // winding decides the front; normals only bend it
    }
    if (m.HasUvs()) {  // [texture]
        for (int k = 0; k < 2; ++k) h.uv[k] = m.uvs[i0][k] * w0 + m.uvs[i1][k] * hit.u + m.uvs[i2][k] * hit.v;
        h.has_uv = true;
    }
    uint32_t mat = m.material_ids[hit.triangle];
    static const SurfaceMaterial kBlack = [] {
        SurfaceMaterial s;
        s.black = true;
        return s;
    }();
    h.material = mat < scene_.materials.size() ? &scene_.materials[mat] : &kBlack;
    if (h.has_uv && h.material->textures) {
        // The texture filter footprint as the camera would see this point (pbrt-v4's approximation for every
        // vertex of a path, Camera::Approximate_dp_dxy): a cone of one pixel's spread from the camera, widened
        // by the incidence and carried to texture space by the triangle's texture-to-world scale (Ray Tracing
        // Gems ch. 20). Secondary vertices see a sharper texture than their real footprint: conservative.
        const auto& t0 = m.uvs[i0];
        const auto& t1 = m.uvs[i1];
        const auto& t2 = m.uvs[i2];
        const float uv_area = 0.5f * std::abs((t1[0] - t0[0]) * (t2[1] - t0[1]) - (t2[0] - t0[0]) * (t1[1] - t0[1]));
        const float world_area =
            0.5f * Length(Cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]));
        const float cone_width = Length(h.p - scene_.camera->position()) * scene_.camera->PixelSpreadAngle();
        h.footprint = imaging::RayConeFootprint(cone_width, Dot(dir, h.ng), uv_area, world_area);
    }
    return h;
}

void Engine::Escape(const RayRecord& r) {
    if (r.kind != kPathRay) return;  // photons leaving the model carry nothing back
    SampledSpectrum L;
    if (scene_.sky) {
        // The sky is also next-event estimated: weight the BSDF-sampled escape against it, at the vertex the
        // direction was sampled from.
        float w = 1;
        if (r.depth > 0 && !(r.flags & kSpecularBounce)) {
            w = PowerHeuristic(r.prev_pdf, SkyPdf(r.origin - r.dir * r.since_vertex, r.dir));
        }
        L += scene_.SkyRadiance(r.dir, r.lambda) * w;
    }
    if (scene_.sun >= 0) {
        const Light& sun = scene_.lights[size_t(scene_.sun)];
        if (Dot(r.dir, sun.to_light) >= sun.cos_sun) {
            // A BSDF-sampled direction that found the sun: weighted against next-event estimation of the
            // sun (power heuristic). Camera rays and specular bounces cannot be light-sampled: weight 1.
            float w = 1;
            if (r.depth > 0 && !(r.flags & kSpecularBounce)) {
                w = PowerHeuristic(r.prev_pdf, UniformConePdf(sun.cos_sun));
            }
            L += sun.spectrum.Sample(r.lambda) * w;
        }
    }
    if (!L.IsZero()) film_->AddSample(r.pixel, r.beta * L, r.lambda);
}

bool Engine::ShadowThroughBrick(RayRecord& r, const ResidentBrick& brick, float t1, LocalCounters& c) const {
    float t0 = r.t_enter;
    for (;;) {
        ++c.shadow_segments;
        if (!has_thin_glass_) return !brick.Occluded(r.origin, r.dir, t0, t1);
        BrickHit hit;
        if (!brick.Intersect(r.origin, r.dir, t0, t1, &hit)) return true;
        SurfaceHit h = MakeSurfaceHit(brick, hit, r.dir);
        const SurfaceMaterial& m = *h.material;
        const ThinGlassMaterial* glass = m.thin_glass();
        if (glass == nullptr) return false;
        SampledSpectrum reflected, transmitted;
        ThinDielectricBxdf(glass->eta.Sample(r.lambda), m.GlassInternalTransmittance(h.has_uv ? &h.uv : nullptr, r.lambda))
            .ReflectanceTransmittance(Dot(r.dir, h.ns), &reflected, &transmitted);
        r.beta *= transmitted;
        if (r.beta.IsZero()) return false;
        t0 = hit.t + 1e-5f * (1.f + std::abs(hit.t));  // past this pane
    }
}

void Engine::Spawn(RayRecord r, uint32_t b, const ResidentBrick* brick, Outbox& out, LocalCounters& c) {
    ++c.rays;
    uint32_t next = Route(r, 0, store::kNoBrick);
    if (next == store::kNoBrick) {
        if (r.kind == kShadowRay) {
            film_->AddSample(r.pixel, r.beta, r.lambda);
        } else {
            Escape(r);
        }
        return;
    }
    if (next == b && brick != nullptr && r.kind == kShadowRay) {
        ProcessRay(r, b, *brick, out, c);  // same brick, resident now: no need to queue
        return;
    }
    if (next != b) ++c.moves;
    out.emplace_back(next, r);
}

void Engine::SampleLight(const Light& light, int index, const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo,
                         const RayRecord& r, const VertexRng& rng, bool mis, uint32_t b, const ResidentBrick& brick,
                         Outbox& out, LocalCounters& c) {
    Point2f u(rng.Uniform(kDimLight0 + 2 * index), rng.Uniform(kDimLight0 + 2 * index + 1));
    Vec3f wi;
    SampledSpectrum Li;
    float t_max = kInfinity;
    float light_pdf = 0;  // solid angle; 0 for delta lights
    switch (light.kind) {
        case Light::Kind::kSun: {
            // Uniform over the solar disc's cone (radiance constant over the disc: no limb darkening).
            wi = Frame::FromZ(light.to_light).FromLocal(SampleUniformCone(u, light.cos_sun));
            light_pdf = UniformConePdf(light.cos_sun);
            Li = light.spectrum.Sample(r.lambda) / light_pdf;
            break;
        }
        case Light::Kind::kDirectional:
            // The paper's eq. 3: L_r = F_r(w_s, w_o) L_s (n . w_s), with L_s the irradiance at normal incidence.
            wi = light.to_light;
            Li = light.spectrum.Sample(r.lambda);
            break;
        case Light::Kind::kPoint:
        case Light::Kind::kSpot: {
            Vec3f d = light.position - h.p;
            float dist2 = Dot(d, d);
            if (dist2 == 0) return;
            float dist = std::sqrt(dist2);
            wi = d / dist;
            float falloff = 1;
            if (light.kind == Light::Kind::kSpot) {
                // Smoothstep between the cone and the start of the falloff (pbrt-v4 SpotLight::I).
                float cos_a = Dot(-wi, light.spot_axis);
                float x = std::clamp((cos_a - light.cos_cone) / std::max(1e-6f, light.cos_falloff - light.cos_cone),
                                     0.f, 1.f);
                falloff = x * x * (3 - 2 * x);
            }
            Li = light.spectrum.Sample(r.lambda) * (falloff / dist2);
            t_max = dist * (1 - 1e-4f);
            break;
        }
    }
    if (Li.IsZero()) return;
    SampledSpectrum f = bsdf.Eval(wo, wi, r.lambda) * std::abs(Dot(wi, h.ns));
    if (f.IsZero()) return;
    float w = 1;
    if (light_pdf > 0 && mis) w = PowerHeuristic(light_pdf, bsdf.Pdf(wo, wi, r.lambda));
    RayRecord s = r;
    s.kind = kShadowRay;
    s.origin = OffsetOrigin(h.p, h.ng, wi);
    s.dir = wi;
    s.t_max = t_max;
    s.beta = r.beta * f * Li * w;
    Spawn(s, b, &brick, out, c);
}

void Engine::SampleSky(const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo, const RayRecord& r,
                       const VertexRng& rng, bool mis, uint32_t b, const ResidentBrick& brick, Outbox& out, LocalCounters& c) {
    const uint32_t dim = kDimLight0 + 2 * uint32_t(scene_.lights.size());
    Vec3f wi;
    if (sky_portals_ && rng.Uniform(dim + 2) < kPortalSkyShare) {
        const Vec3f q = SamplePortalPoint(rng.Uniform(dim + 3), Point2f(rng.Uniform(dim), rng.Uniform(dim + 1)));
        const float d = Length(q - h.p);
        if (!(d > 0)) return;
        wi = (q - h.p) / d;
    } else {
        wi = SampleUniformSphere(Point2f(rng.Uniform(dim), rng.Uniform(dim + 1)));
    }
    SampledSpectrum f = bsdf.Eval(wo, wi, r.lambda) * std::abs(Dot(wi, h.ns));
    if (f.IsZero()) return;
    const float light_pdf = SkyPdf(h.p, wi);
    if (!(light_pdf > 0)) return;
    float w = mis ? PowerHeuristic(light_pdf, bsdf.Pdf(wo, wi, r.lambda)) : 1.f;
    RayRecord s = r;
    s.kind = kShadowRay;
    s.origin = OffsetOrigin(h.p, h.ng, wi);
    s.dir = wi;
    s.t_max = kInfinity;
    s.beta = r.beta * f * scene_.SkyRadiance(wi, r.lambda) * (w / light_pdf);
    if (s.beta.IsZero()) return;
    Spawn(s, b, &brick, out, c);
}

bool Engine::ShadePath(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit, Outbox& out,
                       LocalCounters& c) {
    SurfaceHit h = MakeSurfaceHit(brick, hit, r.dir);
    const SurfaceMaterial& mat = *h.material;
    const Vec3f wo = -r.dir;
    if (r.depth == 0) film_->AddAov(r.pixel, Vec3f(1, 1, 1) * mat.AlbedoForAov(), h.ns, hit.t);
    if (mat.emissive) {
        // Emission found by the path itself (two-sided; emissive surfaces are not light-sampled, so weight
        // 1). In photon mode paths stop at their first diffuse vertex, so this only sees specular and glossy
        // chains; light reaching diffuse vertices from emitters comes with the photons.
        film_->AddSample(r.pixel, r.beta * mat.Emitted(h.has_uv ? &h.uv : nullptr, r.lambda), r.lambda);
    }
    // A path at its last scattering still passes through thin glass (not a scattering event): cut there,
    // the light that next-event estimation left to BSDF sampling through a window would be lost.
    const bool last = r.depth >= uint32_t(scene_.settings.max_depth);
    if (last && mat.thin_glass() == nullptr) return false;
    Bsdf bsdf = mat.MakeBsdf(h.ns, &r.lambda, h.has_uv ? &h.uv : nullptr, h.footprint);
    const uint8_t flags = bsdf.Flags();
    if (flags == kBxdfUnset) return false;
    VertexRng rng(Key(r, kStreamPath));
    const bool non_specular = flags & (kBxdfDiffuse | kBxdfGlossy);
    // In photon mode the path stops at its first diffuse vertex: no BSDF-sampled direction will find the
    // lights from here, so next-event estimation takes the full weight.
    const bool visible_point = scene_.settings.mode == RenderSettings::Mode::kPhoton && (flags & kBxdfDiffuse);
    if (non_specular) {
        for (size_t i = 0; i < scene_.lights.size(); ++i) {
            SampleLight(scene_.lights[i], int(i), h, bsdf, wo, r, rng, !visible_point, b, brick, out, c);
        }
        if (scene_.sky) SampleSky(h, bsdf, wo, r, rng, !visible_point, b, brick, out, c);
    }
    if (visible_point) {
        // SPPM: the path stops at its first diffuse vertex; indirect light there comes from photons.
        visible_->Add(r.pixel, h.p, h.ns, wo, mat, h.has_uv ? &h.uv : nullptr, h.footprint, r.beta);
        return false;
    }
    std::optional<BsdfSample> bs = bsdf.Sample(wo, rng.Uniform(kDimBsdfChoice),
                                               Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)), r.lambda);
    if (!bs) return false;
    r.beta *= bs->f * (std::abs(Dot(bs->wi, h.ns)) / bs->pdf);
    r.vertex += 1;
    if (IsPassThrough(mat, *bs)) {
        if (r.beta.IsZero()) return false;
        r.since_vertex += Length(h.p - r.origin);
        r.origin = OffsetOrigin(h.p, h.ng, bs->wi);
        r.t_max = kInfinity;
        return true;
    }
    if (last) return false;
    r.flags = bs->IsSpecular() ? kSpecularBounce : 0;
    r.prev_pdf = bs->pdf;
    if (r.depth >= 2) {
        // Russian roulette (Arvo & Kirk 1990) once the throughput is below 1.
        float m = r.beta.MaxValue();
        if (m < 1) {
            float q = std::max(0.f, 1 - m);
            if (rng.Uniform(kDimRoulette) < q) return false;
            r.beta /= 1 - q;
        }
    }
    if (r.beta.IsZero()) return false;
    r.origin = OffsetOrigin(h.p, h.ng, bs->wi);
    r.since_vertex = 0;
    r.dir = bs->wi;
    r.t_max = kInfinity;
    r.depth += 1;
    return true;
}

bool Engine::ShadePhoton(RayRecord& r, uint32_t b, const ResidentBrick& brick, const BrickHit& hit) {
    SurfaceHit h = MakeSurfaceHit(brick, hit, r.dir);
    const SurfaceMaterial& mat = *h.material;
    const Vec3f wo = -r.dir;
    Bsdf bsdf = mat.MakeBsdf(h.ns, &r.lambda, h.has_uv ? &h.uv : nullptr, h.footprint);
    const uint8_t flags = bsdf.Flags();
    if (flags == kBxdfUnset) return false;
    // Direct light from the sun and the other delta or disc lights is next-event estimated at the visible
    // points: deposit only photons that bounced, or that come from emitters no estimator samples.
    if ((r.depth > 0 || (r.flags & kFromAreaLight)) && (flags & kBxdfDiffuse)) {
        visible_->Deposit(b, h.p, h.ng, wo, r.beta, r.lambda);
    }
    // As for paths, a photon at its last bounce still passes through thin glass.
    const bool last = uint32_t(r.depth) + 1 >= uint32_t(scene_.settings.max_depth);
    if (last && mat.thin_glass() == nullptr) return false;
    VertexRng rng(Key(r, kStreamPhoton));
    std::optional<BsdfSample> bs =
        bsdf.Sample(wo, rng.Uniform(kDimBsdfChoice), Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)),
                    r.lambda, TransportMode::kImportance);
    if (!bs) return false;
    SampledSpectrum beta = r.beta * bs->f * (std::abs(Dot(bs->wi, h.ns)) / bs->pdf);
    r.vertex += 1;
    if (IsPassThrough(mat, *bs)) {
        // Through a window pane: not a bounce, so a photon that arrives next at a diffuse surface is still
        // direct sunlight, which next-event estimation through glass already counts.
        r.beta = beta;
        if (r.beta.IsZero()) return false;
        r.origin = OffsetOrigin(h.p, h.ng, bs->wi);
        r.t_max = kInfinity;
        return true;
    }
    if (last) return false;
    // Russian roulette on the photon's change of power (pbrt-v4 SPPM photon pass).
    float q = std::max(0.f, 1 - beta.Average() / std::max(1e-20f, r.beta.Average()));
    if (rng.Uniform(kDimRoulette) < q) return false;
    r.beta = beta / (1 - q);
    if (r.beta.IsZero()) return false;
    r.origin = OffsetOrigin(h.p, h.ng, bs->wi);
    r.dir = bs->wi;
    r.t_max = kInfinity;
    r.depth += 1;
    return true;
}

void Engine::ProcessRay(RayRecord r, uint32_t b, const ResidentBrick& brick, Outbox& out, LocalCounters& c) {
    for (;;) {
        const float t1 = std::min(SegmentEndWithSlack(r.t_exit), r.t_max);
        if (r.kind == kShadowRay) {
            if (!ShadowThroughBrick(r, brick, t1, c)) return;
            uint32_t next = Route(r, r.t_exit, b);
            if (next == store::kNoBrick) {
                film_->AddSample(r.pixel, r.beta, r.lambda);  // unoccluded all the way
            } else {
                ++c.moves;
                out.emplace_back(next, r);
            }
            return;
        }
        ++c.segments;
        BrickHit hit;
        if (!brick.Intersect(r.origin, r.dir, r.t_enter, t1, &hit)) {
            uint32_t next = Route(r, r.t_exit, b);
            if (next == store::kNoBrick) {
                Escape(r);
            } else {
                ++c.moves;
                out.emplace_back(next, r);
            }
            return;
        }
        bool go_on = r.kind == kPhotonRay ? ShadePhoton(r, b, brick, hit) : ShadePath(r, b, brick, hit, out, c);
        if (!go_on) return;
        ++c.rays;
        uint32_t next = Route(r, 0, store::kNoBrick);
        if (next == store::kNoBrick) {
            Escape(r);
            return;
        }
        if (next == b) continue;  // still in this brick: keep tracing without queueing
        ++c.moves;
        out.emplace_back(next, r);
        return;
    }
}

void Engine::Flush(Outbox& out, const LocalCounters& c) {
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<RayRecord> group;
    for (size_t i = 0; i < out.size();) {
        size_t j = i;
        group.clear();
        while (j < out.size() && out[j].first == out[i].first) group.push_back(out[j++].second);
        queues_.Push(out[i].first, group.data(), group.size());
        i = j;
    }
    out.clear();
    segments_.fetch_add(c.segments, std::memory_order_relaxed);
    shadow_segments_.fetch_add(c.shadow_segments, std::memory_order_relaxed);
    moves_.fetch_add(c.moves, std::memory_order_relaxed);
    rays_.fetch_add(c.rays, std::memory_order_relaxed);
}

Status Engine::Drain(size_t stop_below) {
    std::vector<RayRecord> batch;
    std::vector<size_t> waiting(queues_.brick_count());
    for (;;) {
        size_t total = 0;
        for (uint32_t i = 0; i < queues_.brick_count(); ++i) total += waiting[i] = queues_.Waiting(i);
        if (total <= stop_below) break;
        const uint32_t b = pager_ && !custom_picker_ ? pager_->Pick(waiting) : picker_(waiting, *scene_.source);
        NAVE_CHECK(b < waiting.size() && waiting[b] > 0) << "the brick picker chose brick " << b
                                                         << " which has no rays waiting";
        stats_->peak_queue_bytes = std::max<uint64_t>(stats_->peak_queue_bytes, queues_.MemoryBytes());
        // If b must be loaded now, the loader loads the next brick meanwhile: two loads at once while the
        // workers would idle anyway.
        if (pager_ && !scene_.source->IsResident(b)) pager_->Prefetch(waiting, b, 0);
        NAVE_ASSIGN_OR_RETURN(BrickHandle handle, AcquireBrick(b));
        queues_.Take(b, kMaxBatch, &batch);
        batches_.fetch_add(1, std::memory_order_relaxed);
        if (pager_) {
            waiting[b] -= batch.size();
            pager_->Prefetch(waiting, b, batch.size());  // loads the next brick while this batch is traced
        }
        const ResidentBrick& brick = *handle;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, batch.size(), kChunk), [&](const tbb::blocked_range<size_t>& range) {
            Outbox out;
            LocalCounters c;
            for (size_t i = range.begin(); i != range.end(); ++i) ProcessRay(batch[i], b, brick, out, c);
            Flush(out, c);
        });
        if (pager_) {
            handle.Reset();
            pager_->BatchDone();
        }
    }
    return Status::Ok();
}

void Engine::GenerateCameraRays(uint64_t first, uint64_t last, uint32_t sample, const SampledWavelengths* lambda) {
    const Camera& camera = *scene_.camera;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, last, 1024), [&](const auto& range) {
        Outbox out;
        LocalCounters c;
        for (uint64_t p = range.begin(); p != range.end(); ++p) {
            RayRecord r{};
            r.kind = kPathRay;
            r.pixel = uint32_t(p);
            r.sample = sample;
            VertexRng rng(Key(r, kStreamCamera));
            float x = float(p % uint64_t(camera.width())) + rng.Uniform(kDimPixelX);
            float y = float(p / uint64_t(camera.width())) + rng.Uniform(kDimPixelY);
            camera.GenerateRay(x, y, rng.Uniform(kDimLens0), rng.Uniform(kDimLens1), &r.origin, &r.dir);
            r.lambda = lambda ? *lambda : SampledWavelengths::SampleVisible(rng.Uniform(kDimLambda));
            r.beta = SampledSpectrum(1.f);
            r.t_max = kInfinity;
            Spawn(r, store::kNoBrick, nullptr, out, c);
        }
        Flush(out, c);
    });
}

Status Engine::RunPath() {
    NAVE_RETURN_IF_ERROR(BuildSkyPortals());
    const Camera& camera = *scene_.camera;
    const uint64_t pixels = uint64_t(camera.width()) * camera.height();
    const int spp = scene_.settings.spp;
    const uint64_t wave = scene_.settings.wave_paths;
    ProgressBar progress("render", pixels * uint64_t(spp), "paths");
    auto start = std::chrono::steady_clock::now();
    int passes = 0;
    // Small images put several passes in one wave, so that the streams stay long enough to keep every thread
    // busy; large images split a pass into waves to bound the memory of the queues.
    const int passes_per_wave = int(std::clamp<uint64_t>(wave / pixels, 1, uint64_t(spp)));
    for (int s = 0; s < spp; s += passes_per_wave) {
        const int s_end = std::min(spp, s + passes_per_wave);
        for (uint64_t first = 0; first < pixels; first += wave) {
            const uint64_t last = std::min(pixels, first + wave);
            for (int k = s; k < s_end; ++k) GenerateCameraRays(first, last, uint32_t(k), nullptr);
            NAVE_RETURN_IF_ERROR(Drain(WaveOverlap()));
            progress.Add((last - first) * uint64_t(s_end - s));
        }
        passes = s_end;
        double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (scene_.settings.time_limit_s > 0 && elapsed >= scene_.settings.time_limit_s) break;
    }
    NAVE_RETURN_IF_ERROR(Drain());  // the last wave's tail
    progress.Finish();
    stats_->samples_per_pixel = passes;
    stats_->camera_paths = pixels * uint64_t(passes);
    film_->SetSamplesPerPixel(passes);
    return Status::Ok();
}

namespace {
/// A rough power of a spectrum for choosing emitters: its mean over 400-700 nm.
float MeanVisible(const Spectrum& s) {
    double sum = 0;
    for (int l = 400; l <= 700; l += 10) sum += s.Evaluate(float(l));
    return float(sum / 31);
}

/// The rough power of an emissive material for choosing emitters: MeanVisible of its spectrum, or for an
/// emission texture the mean of its mean radiance over a few wavelength sets (any positive weight keeps the
/// estimate unbiased; a good one only lowers noise).
float EmissionPower(const SurfaceMaterial& m) {
    if (!(m.textures && m.textures->emission)) return MeanVisible(m.emission);
    double sum = 0;
    for (int i = 0; i < 8; ++i) {
        SampledWavelengths lambda = SampledWavelengths::SampleVisible((i + 0.5f) / 8);
        SampledSpectrum s = m.textures->MeanEmission(lambda);
        for (int k = 0; k < kNumWavelengths; ++k) sum += s[k];
    }
    // A black texture would give 0 and never be chosen; keep a floor so its triangles can still emit.
    return std::max(float(sum / (8 * kNumWavelengths)), 1e-6f);
}
}  // namespace

Status Engine::ForEachOwnedTriangle(const std::function<bool(const SurfaceMaterial&)>& want,
                                    const std::function<void(const store::BrickMesh&, size_t, uint32_t)>& visit) {
    for (uint32_t b = 0; b < scene_.source->brick_count(); ++b) {
        NAVE_ASSIGN_OR_RETURN(BrickHandle h, AcquireBrick(b));  // released at the end of the iteration
        const store::BrickMesh& m = h->mesh();
        for (size_t t = 0; t < m.TriangleCount(); ++t) {
            const uint32_t mat = m.material_ids[t];
            if (mat >= scene_.materials.size() || !want(scene_.materials[mat])) continue;
            const std::array<Vec3f, 3> v = m.TrianglePositions(t);
            if (tree_.Locate((v[0] + v[1] + v[2]) * (1.f / 3.f)) == b) visit(m, t, b);
        }
    }
    return Status::Ok();
}

Vec3f Engine::SamplePortalPoint(double u_triangle, Point2f u, size_t* triangle) const {
    size_t i = size_t(std::upper_bound(portal_area_cdf_.begin() + 1, portal_area_cdf_.end(), u_triangle) -
                      (portal_area_cdf_.begin() + 1));
    i = std::min(i, portal_triangles_.size() - 1);
    if (triangle != nullptr) *triangle = i;
    const std::array<float, 3> w = SampleUniformTriangle(u);
    const auto& t = portal_triangles_[i];
    return t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
}

Status Engine::SetPortals(const std::vector<std::array<Vec3f, 3>>& triangles) {
    store::BrickMesh mesh;
    portal_area_ = 0;
    portal_area_cdf_.assign(1, 0.0);
    for (const auto& t : triangles) {
        uint32_t base = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {t[0], t[1], t[2]});
        mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
        mesh.material_ids.push_back(0);
        portal_area_ += 0.5 * double(Length(Cross(t[1] - t[0], t[2] - t[0])));
        portal_area_cdf_.push_back(portal_area_);
    }
    for (double& c : portal_area_cdf_) c /= portal_area_;
    portal_triangles_ = triangles;
    NAVE_ASSIGN_OR_RETURN(portal_scene_, ResidentBrick::Build(scene_.source->device(), 0, scene_.source->bounds(),
                                                              std::move(mesh)));
    return Status::Ok();
}

Status Engine::BuildSkyPortals() {
    if (!scene_.sky || scene_.settings.sky_sampling != RenderSettings::SkySampling::kPortals) return Status::Ok();
    if (scene_.settings.mode == RenderSettings::Mode::kPhoton) {
        // Photons from the sky are aimed at the portals only with photon_target = "portals"; the visible
        // points' sky sampling shares those portals rather than changing where photons go.
        if (!portal_scene_) {
            log::Warning("render.sky_sampling = \"portals\" in photon mode needs render.photon_target = "
                         "\"portals\"; the sky is sampled uniformly");
        }
        sky_portals_ = portal_scene_ != nullptr;
        return Status::Ok();
    }
    std::vector<std::array<Vec3f, 3>> triangles;
    if (std::none_of(scene_.materials.begin(), scene_.materials.end(), [](const auto& m) { return m.portal; })) {
        return InvalidArgumentError("render.sky_sampling = \"portals\" but no material has portal = true");
    }
    NAVE_RETURN_IF_ERROR(ForEachOwnedTriangle([](const SurfaceMaterial& m) { return m.portal; },
                                              [&](const store::BrickMesh& m, size_t t, uint32_t) {
                                                  triangles.push_back(m.TrianglePositions(t));
                                              }));
    if (triangles.empty()) {
        return InvalidArgumentError("render.sky_sampling = \"portals\" but the model has no triangle of a "
                                    "portal material");
    }
    NAVE_RETURN_IF_ERROR(SetPortals(triangles));
    sky_portals_ = true;
    return Status::Ok();
}

float Engine::SkyPdf(const Vec3f& p, const Vec3f& w) const {
    if (!sky_portals_) return UniformSpherePdf();
    double portal_pdf = 0;
    ForEachPortalCrossing(p, w, kInfinity, [&](const BrickHit& hit) {
        const float cos_theta = std::abs(Dot(Normalize(hit.ng), w));
        if (cos_theta > 1e-6f) portal_pdf += double(hit.t) * hit.t / (double(cos_theta) * portal_area_);
    });
    return float((1 - kPortalSkyShare) * UniformSpherePdf() + kPortalSkyShare * portal_pdf);
}

Status Engine::BuildEmitters() {
    const Bounds3f& bounds = scene_.source->bounds();
    scene_center_ = bounds.Center();
    scene_radius_ = std::max(1e-3f, 0.5f * Length(bounds.Diagonal()));
    const float disk_area = 3.14159265358979f * scene_radius_ * scene_radius_;
    const float kPiF = 3.14159265358979f;

    // One pass over the bricks that hold emissive or portal materials. A triangle stored in several bricks
    // (it crosses cells) is kept only in the brick whose cell holds its centroid.
    const bool want_portals = scene_.settings.photon_target == RenderSettings::PhotonTarget::kPortals;
    bool any_emissive = false, any_portal = false;
    for (const SurfaceMaterial& m : scene_.materials) {
        any_emissive |= m.emissive;
        any_portal |= m.portal;
    }
    if (want_portals && !any_portal) {
        return InvalidArgumentError("render.photon_target = \"portals\" but no material has portal = true");
    }
    std::vector<double> weights;
    std::vector<Emitter> triangles;
    std::vector<double> triangle_weights;
    std::vector<std::array<Vec3f, 3>> portal_triangles;
    if (any_emissive || (want_portals && any_portal)) {
        // Per material, not per triangle: an emission texture's mean takes texture lookups.
        std::vector<float> power(scene_.materials.size(), 0.f);
        for (size_t i = 0; i < power.size(); ++i) {
            if (scene_.materials[i].emissive) power[i] = EmissionPower(scene_.materials[i]);
        }
        NAVE_RETURN_IF_ERROR(ForEachOwnedTriangle(
            [&](const SurfaceMaterial& sm) { return sm.emissive || (want_portals && sm.portal); },
            [&](const store::BrickMesh& m, size_t t, uint32_t) {
                const SurfaceMaterial& sm = scene_.materials[m.material_ids[t]];
                const std::array<Vec3f, 3> v = m.TrianglePositions(t);
                if (want_portals && sm.portal) portal_triangles.push_back(v);
                if (!sm.emissive) return;
                Emitter e;
                e.kind = Emitter::Kind::kTriangle;
                e.v0 = v[0];
                e.v1 = v[1];
                e.v2 = v[2];
                Vec3f c = Cross(v[1] - v[0], v[2] - v[0]);
                e.area = 0.5f * Length(c);
                if (e.area <= 0) return;
                e.n = Normalize(c);
                e.material = &sm;
                if (m.HasUvs()) {
                    for (int k = 0; k < 3; ++k) e.uv[k] = m.uvs[m.indices[3 * t + k]];
                    e.has_uv = true;
                }
                triangles.push_back(e);
                // Two-sided Lambertian emitter: power = L pi A per side.
                triangle_weights.push_back(power[m.material_ids[t]] * 2 * kPiF * e.area);
            }));
    }
    for (const Light& l : scene_.lights) {
        Emitter e;
        e.light = &l;
        float w = MeanVisible(l.spectrum);
        float target_area = disk_area;
        if (want_portals && (l.kind == Light::Kind::kSun || l.kind == Light::Kind::kDirectional)) {
            PortalProjection projection(portal_triangles, l.to_light);
            if (!projection.empty()) {
                e.portal = int(portals_.size());
                target_area = float(projection.total_area());
                portals_.push_back(std::move(projection));
            }
        }
        switch (l.kind) {
            case Light::Kind::kSun: w *= l.SunSolidAngle() * target_area; break;
            case Light::Kind::kDirectional: w *= target_area; break;
            case Light::Kind::kPoint:
            case Light::Kind::kSpot: w *= 4 * kPiF; break;
        }
        emitters_.push_back(e);
        weights.push_back(w);
    }
    if (scene_.sky && want_portals && !portal_triangles.empty()) NAVE_RETURN_IF_ERROR(SetPortals(portal_triangles));
    if (scene_.sky) {
        Emitter e;
        e.kind = Emitter::Kind::kSky;
        emitters_.push_back(e);
        // Mean radiance over the sphere of directions (a fixed 256-direction Fibonacci set for a sky model).
        double mean = 0;
        if (scene_.preetham) {
            const int n = 256;
            for (int i = 0; i < n; ++i) {
                float z = 1 - 2 * (float(i) + 0.5f) / float(n), phi = 2.39996323f * float(i);
                float rxy = std::sqrt(std::max(0.f, 1 - z * z));
                mean += MeanVisible(scene_.preetham->RadianceSpectrum(Vec3f(rxy * std::cos(phi), rxy * std::sin(phi), z)));
            }
            mean = mean / n * scene_.sky_scale;
        } else {
            mean = MeanVisible(scene_.sky_radiance);
        }
        // Through portals: lines cross them with measure 2 pi A_portals (both sides), through the bounds 4 pi A_disc.
        weights.push_back(mean * (portal_scene_ ? 2 * kPiF * portal_area_ : 4 * kPiF * disk_area));
    }
    emitters_.insert(emitters_.end(), triangles.begin(), triangles.end());
    weights.insert(weights.end(), triangle_weights.begin(), triangle_weights.end());
    double total = 0;
    for (double w : weights) total += w;
    if (emitters_.empty() || !(total > 0)) {
        return InvalidArgumentError("photon mode needs a light: the scene has no sun, light, sky or emissive "
                                    "material with power");
    }
    emitter_cdf_.assign(1, 0.0);
    for (double w : weights) emitter_cdf_.push_back(emitter_cdf_.back() + w / total);
    emitter_cdf_.back() = 1.0;
    return Status::Ok();
}

void Engine::EmitPhotons(uint64_t first, uint64_t last, const SampledWavelengths& lambda) {
    const float kPiF = 3.14159265358979f;
    const float disk_area = kPiF * scene_radius_ * scene_radius_;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, last, 1024), [&](const auto& range) {
        Outbox out;
        LocalCounters c;
        for (uint64_t i = range.begin(); i != range.end(); ++i) {
            RayRecord r{};
            r.kind = kPhotonRay;
            r.pixel = uint32_t(i);
            r.lambda = lambda;
            r.t_max = kInfinity;
            VertexRng rng(Key(r, kStreamEmit));
            float u = rng.Uniform(0);
            size_t k = size_t(std::upper_bound(emitter_cdf_.begin() + 1, emitter_cdf_.end(), double(u)) -
                              (emitter_cdf_.begin() + 1));
            k = std::min(k, emitters_.size() - 1);
            const float p_choice = float(emitter_cdf_[k + 1] - emitter_cdf_[k]);
            if (p_choice <= 0) continue;
            const Emitter& e = emitters_[k];
            Point2f u1(rng.Uniform(1), rng.Uniform(2)), u2(rng.Uniform(3), rng.Uniform(4));
            // Photons from distant sources (sun, directional, sky) start on a disc facing the source that
            // covers the model's bounding sphere: every photon that can reach the model does (the model's
            // bounds projected onto the light's direction; windows are reached through them).
            auto disc_origin = [&](const Vec3f& toward) {
                Frame f = Frame::FromZ(toward);
                Point2f d = SampleUniformDiskConcentric(u1);
                return scene_center_ + toward * (2 * scene_radius_) + f.x * (d.x * scene_radius_) +
                       f.y * (d.y * scene_radius_);
            };
            if (e.kind == Emitter::Kind::kLight) {
                const Light& l = *e.light;
                switch (l.kind) {
                    case Light::Kind::kSun:
                    case Light::Kind::kDirectional: {
                        const bool sun = l.kind == Light::Kind::kSun;
                        Vec3f to = sun ? Frame::FromZ(l.to_light).FromLocal(SampleUniformCone(u2, l.cos_sun))
                                       : l.to_light;
                        // Area density of the start point on the plane facing the light: 1/A on the disc,
                        // count(x)/A_total on the portals' projections (photon_portals.h).
                        float area = disk_area;
                        if (e.portal >= 0) {
                            const PortalProjection& portals = portals_[size_t(e.portal)];
                            int coverage = 1;
                            Vec3f p = portals.Sample(rng.Uniform(6), u1.x, u1.y, &coverage);
                            r.origin = p + to * (2 * scene_radius_);
                            area = float(portals.total_area()) / float(coverage);
                        } else {
                            r.origin = disc_origin(l.to_light);
                        }
                        r.dir = -to;
                        // Sun: L cos / (p_area p_dir) with p_dir = 1/Omega; directional: E / p_area.
                        r.beta = sun ? l.spectrum.Sample(lambda) * (Dot(to, l.to_light) * area * l.SunSolidAngle())
                                     : l.spectrum.Sample(lambda) * area;
                        break;
                    }
                    case Light::Kind::kPoint:
                    case Light::Kind::kSpot: {
                        r.origin = l.position;
                        r.dir = SampleUniformSphere(u2);
                        float falloff = 1;
                        if (l.kind == Light::Kind::kSpot) {
                            float cos_a = Dot(r.dir, l.spot_axis);
                            float x = std::clamp((cos_a - l.cos_cone) / std::max(1e-6f, l.cos_falloff - l.cos_cone),
                                                 0.f, 1.f);
                            falloff = x * x * (3 - 2 * x);
                        }
                        r.beta = l.spectrum.Sample(lambda) * (falloff * 4 * kPiF);
                        break;
                    }
                }
            } else if (e.kind == Emitter::Kind::kSky && portal_scene_) {
                // A point uniform on the portals' area, a cosine-weighted direction on a random side: the
                // line's density is count / (2 pi A) in the measure dA_perp dw, count = portals the line
                // crosses (Veach's balance heuristic over the portals), so the power is L 2 pi A / count.
                size_t i = 0;
                const Vec3f p = SamplePortalPoint(rng.Uniform(6), u1, &i);
                const auto& t = portal_triangles_[i];
                Vec3f n = Normalize(Cross(t[1] - t[0], t[2] - t[0]));
                if (rng.Uniform(5) < 0.5f) n = -n;
                Vec3f d = Frame::FromZ(n).FromLocal(SampleCosineHemisphere(u2));
                r.origin = p - d * (2 * scene_radius_);
                r.dir = d;
                const int count = ForEachPortalCrossing(r.origin, d, 4 * scene_radius_, [](const BrickHit&) {});
                r.beta = scene_.SkyRadiance(-d, lambda) * float(2 * kPiF * portal_area_ / std::max(1, count));
            } else if (e.kind == Emitter::Kind::kSky) {
                Vec3f to = SampleUniformSphere(u2);
                r.origin = disc_origin(to);
                r.dir = -to;
                r.beta = scene_.SkyRadiance(to, lambda) * (4 * kPiF * disk_area);
                // Direct skylight is next-event estimated at the visible points: sky photons deposit only
                // after a bounce.
            } else {
                // Uniform point on the triangle (Turk 1990 square-root parameterisation), cosine-weighted
                // direction on a side chosen with probability 1/2.
                const std::array<float, 3> w = SampleUniformTriangle(u1);
                Vec3f p = e.v0 * w[0] + e.v1 * w[1] + e.v2 * w[2];
                Vec3f n = rng.Uniform(5) < 0.5f ? e.n : -e.n;
                r.dir = Frame::FromZ(n).FromLocal(SampleCosineHemisphere(u2));
                r.origin = OffsetOrigin(p, n, r.dir);
                // L cos / (1/A * cos/pi * 1/2).
                std::array<float, 2> uv;
                for (int k = 0; k < 2; ++k) uv[k] = e.uv[0][k] * w[0] + e.uv[1][k] * w[1] + e.uv[2][k] * w[2];
                r.beta = e.material->Emitted(e.has_uv ? &uv : nullptr, lambda) * (2 * kPiF * e.area);
                r.flags = kFromAreaLight;
            }
            r.beta /= p_choice;
            if (r.beta.IsZero()) continue;
            Spawn(r, store::kNoBrick, nullptr, out, c);
        }
        Flush(out, c);
    });
}

Status Engine::RunPhoton() {
    const Camera& camera = *scene_.camera;
    const uint64_t pixels = uint64_t(camera.width()) * camera.height();
    const int iterations = scene_.settings.iterations;
    const uint64_t photons = scene_.settings.photons_per_iteration;
    const uint64_t wave = scene_.settings.wave_paths;
    NAVE_RETURN_IF_ERROR(BuildEmitters());
    NAVE_RETURN_IF_ERROR(BuildSkyPortals());
    float radius = scene_.settings.initial_radius_m > 0 ? scene_.settings.initial_radius_m
                                                         : 0.01f * 2 * scene_radius_;
    visible_ = std::make_unique<VisiblePoints>(pixels, scene_.source->brick_count(), radius);
    ProgressBar progress("photon mapping", uint64_t(iterations), "iterations");
    auto start = std::chrono::steady_clock::now();
    int done = 0;
    for (int it = 0; it < iterations; ++it) {
        iteration_ = uint32_t(it);
        SampledWavelengths lambda =
            SampledWavelengths::SampleVisible(VertexRng(RngKey{scene_.settings.seed, 0, 0, 0, iteration_,
                                                               kStreamLambda}).Uniform(0));
        visible_->BeginIteration(lambda);
        // Visible points must all be in place before photons arrive: waves overlap within each pass only.
        for (uint64_t first = 0; first < pixels; first += wave) {
            GenerateCameraRays(first, std::min(pixels, first + wave), 0, &lambda);
            NAVE_RETURN_IF_ERROR(Drain(first + wave < pixels ? WaveOverlap() : 0));
        }
        visible_->BuildBrickGrids(tree_);
        for (uint64_t first = 0; first < photons; first += wave) {
            EmitPhotons(first, std::min(photons, first + wave), lambda);
            NAVE_RETURN_IF_ERROR(Drain(first + wave < photons ? WaveOverlap() : 0));
        }
        visible_->EndIteration(scene_.settings.alpha);
        done = it + 1;
        progress.Add(1);
        double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (scene_.settings.time_limit_s > 0 && elapsed >= scene_.settings.time_limit_s) break;
    }
    progress.Finish();
    // Direct light and specular chains were summed by the film over `done` iterations; the photon estimate
    // is added as `done` times the per-iteration mean so the film's division by its sample count holds.
    film_->SetSamplesPerPixel(done);
    const double emitted = double(photons) * done;
    for (uint64_t p = 0; p < pixels; ++p) {
        film_->AddXYZ(uint32_t(p), visible_->IndirectXYZ(uint32_t(p), emitted) * double(done));
    }
    stats_->iterations = done;
    stats_->samples_per_pixel = done;
    stats_->camera_paths = pixels * uint64_t(done);
    stats_->photons = emitted;
    return Status::Ok();
}

Status Engine::Run() {
    auto start = std::chrono::steady_clock::now();
    BrickSourceStats before = scene_.source->stats();
    Status status = scene_.settings.mode == RenderSettings::Mode::kPath ? RunPath() : RunPhoton();
    NAVE_RETURN_IF_ERROR(status);
    BrickSourceStats after = scene_.source->stats();
    stats_->wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats_->segments_traced = segments_.load();
    stats_->shadow_segments = shadow_segments_.load();
    stats_->brick_moves = moves_.load();
    stats_->rays = rays_.load();
    stats_->batches = batches_.load();
    stats_->brick_loads = after.loads - before.loads;
    stats_->bytes_read = after.bytes_read - before.bytes_read;
    stats_->brick_acquires = after.acquires - before.acquires;
    if (pager_) {
        const PagerStats p = pager_->stats();
        stats_->brick_budget_bytes = p.brick_budget_bytes;
        stats_->peak_brick_bytes = p.peak_resident_bytes;
        stats_->brick_evictions = p.evictions;
        stats_->brick_reloads = p.reloads;
        stats_->prefetch_loads = p.prefetch_loads;
        stats_->prefetch_hits = p.prefetch_hits;
        stats_->brick_acquires = p.acquires;
        stats_->stall_seconds = p.stall_seconds;
    } else {
        stats_->peak_brick_bytes = after.peak_resident_bytes;
        stats_->brick_evictions = after.evictions - before.evictions;
        stats_->stall_seconds = stall_seconds_;
        stats_->prefetch_hits = stats_->brick_acquires - std::min(stats_->brick_acquires, stats_->brick_loads);
    }
    stats_->peak_rss_bytes = PeakRssBytes();
    return Status::Ok();
}

}  // namespace

uint32_t PickFullestBrick(const std::vector<size_t>& waiting, const BrickSource&) {
    return uint32_t(std::max_element(waiting.begin(), waiting.end()) - waiting.begin());
}

Status RenderStreams(const RenderScene& scene, Film* film, RenderStats* stats, BrickPicker picker,
                     const PagerOptions* paging) {
    NAVE_CHECK(film->width() == scene.camera->width() && film->height() == scene.camera->height());
    int threads = scene.settings.threads > 0 ? scene.settings.threads : tbb::this_task_arena::max_concurrency();
    tbb::task_arena arena(threads);
    Status status;
    arena.execute([&] {
        Engine engine(scene, film, stats, std::move(picker));
        status = paging != nullptr ? engine.EnablePaging(*paging) : Status::Ok();
        if (status.ok()) status = engine.Run();
    });
    return status;
}

}  // namespace nave::render
