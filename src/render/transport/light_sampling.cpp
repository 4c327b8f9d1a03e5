#include "src/render/transport/light_sampling.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>

#include "src/core/log.h"
#include "src/core/sampling.h"
#include "src/render/scene/materials/frame.h"
#include "src/render/stream/stream_scheduler.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {

StatusOr<std::unique_ptr<SkyPortals>> SkyPortals::Build(
    const BrickSource& source, std::vector<std::array<Vec3f, 3>> triangles) {
    std::unique_ptr<SkyPortals> portals(new SkyPortals());
    store::BrickMesh mesh;
    portals->area_cdf_.assign(1, 0.0);
    for (const auto& t : triangles) {
        uint32_t base = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {t[0], t[1], t[2]});
        mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
        mesh.material_ids.push_back(0);
        portals->area_ += 0.5 * double(Length(Cross(t[1] - t[0], t[2] - t[0])));
        portals->area_cdf_.push_back(portals->area_);
    }
    for (double& c : portals->area_cdf_) c /= portals->area_;
    portals->triangles_ = std::move(triangles);
    NAVE_ASSIGN_OR_RETURN(portals->scene_,
                          ResidentBrick::Build(source.device(), 0, source.bounds(), mesh));
    return portals;
}

Vec3f SkyPortals::SamplePoint(double u_triangle, Point2f u, size_t* triangle) const {
    size_t i = size_t(std::upper_bound(area_cdf_.begin() + 1, area_cdf_.end(), u_triangle) -
                      (area_cdf_.begin() + 1));
    i = std::min(i, triangles_.size() - 1);
    if (triangle != nullptr) *triangle = i;
    const std::array<float, 3> w = SampleUniformTriangle(u);
    const auto& t = triangles_[i];
    return t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
}

StatusOr<std::unique_ptr<LightSampler>> LightSampler::Create(const RenderScene& scene,
                                                             StreamScheduler& scheduler,
                                                             const SkyPortals* photon_portals,
                                                             double photon_power) {
    std::unique_ptr<LightSampler> sampler(new LightSampler(scene));
    if (!scene.sky || scene.settings.sky_sampling != RenderSettings::SkySampling::kPortals) {
        return sampler;
    }
    if (scene.settings.mode == RenderSettings::Mode::kPhoton) {
        // Photons from the sky are aimed at the portals only with photon_target = "portals"; the
        // visible points' sky sampling shares those portals rather than changing where photons go.
        if (photon_portals == nullptr) {
            log::Warning(
                "render.sky_sampling = \"portals\" in photon mode needs render.photon_target = "
                "\"portals\"; the sky is sampled uniformly");
        }
        sampler->portals_ = photon_portals;
        if (photon_portals != nullptr) {
            sampler->windows_ = std::make_unique<SkyWindows>(
                *photon_portals, scene.source->bounds(), photon_power, TypicalWindowLight(scene));
            log::Info(
                "sky through {} windows ({} portal triangles): the sky's photons and shadow rays "
                "teach each region its own",
                sampler->windows_->window_count(), photon_portals->triangle_count());
        }
        return sampler;
    }
    std::vector<std::array<Vec3f, 3>> triangles;
    if (std::none_of(scene.materials.begin(), scene.materials.end(),
                     [](const auto& m) { return m.portal; })) {
        return InvalidArgumentError(
            "render.sky_sampling = \"portals\" but no material has portal = true");
    }
    // The portals only guide the sky's samples (SkyPdf mixes them with uniform directions and
    // counts the same triangles), so the coarsest levels serve: a tenth of the triangles to read.
    std::vector<uint32_t> bricks;  // of each triangle
    NAVE_RETURN_IF_ERROR(ForEachOwnedTriangle(
        scene, scheduler, ScanDetail::kCoarsest, [](const SurfaceMaterial& m) { return m.portal; },
        [&](const ResidentMesh& m, size_t t, uint32_t b) {
            triangles.push_back(m.TrianglePositions(t));
            bricks.push_back(b);
        }));
    if (RankGroup* ranks = scheduler.ranks()) {
        NAVE_ASSIGN_OR_RETURN(triangles, GatherPortals(*ranks, triangles, bricks));
    }
    if (triangles.empty()) {
        return InvalidArgumentError(
            "render.sky_sampling = \"portals\" but the model has no triangle of a "
            "portal material");
    }
    NAVE_ASSIGN_OR_RETURN(sampler->own_portals_,
                          SkyPortals::Build(*scene.source, std::move(triangles)));
    sampler->portals_ = sampler->own_portals_.get();
    return sampler;
}

StatusOr<std::vector<std::array<Vec3f, 3>>> LightSampler::GatherPortals(
    RankGroup& ranks, const std::vector<std::array<Vec3f, 3>>& triangles,
    const std::vector<uint32_t>& bricks) {
    // The order numbers the triangles the portals sample: every process's must be one process's.
    struct Found {
        uint32_t brick;
        std::array<Vec3f, 3> triangle;
    };
    std::vector<Found> mine(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i) mine[i] = {bricks[i], triangles[i]};
    NAVE_ASSIGN_OR_RETURN(const std::vector<Found> found,
                          GatherInBrickOrder(ranks, std::span<const Found>(mine)));
    std::vector<std::array<Vec3f, 3>> out(found.size());
    for (size_t i = 0; i < found.size(); ++i) out[i] = found[i].triangle;
    return out;
}

double LightSampler::TypicalWindowLight(const RenderScene& scene) {
    // The sky's brightest axis over a window of 0.01 sr (2 m² seen from 14 m).
    const double radiance = scene.sky->BrightestAxisRadiance();
    return radiance > 0 ? radiance * 0.01 : 1.0;
}

std::optional<RayRecord> LightSampler::SampleLight(const Light& light, int index,
                                                   const SurfaceHit& h, const Bsdf& bsdf,
                                                   const Vec3f& wo, const RayRecord& r,
                                                   const VertexRng& rng,
                                                   const GuidedBsdf* continuation) const {
    Point2f u(rng.Uniform(kDimLight0 + 2 * index), rng.Uniform(kDimLight0 + 2 * index + 1));
    const std::optional<LightSample> ls = light.SampleLi(h.p, u, r.lambda);
    if (!ls || ls->weight.IsZero()) return std::nullopt;
    const Vec3f& wi = ls->wi;
    SampledSpectrum f = bsdf.Eval(wo, wi, r.lambda) * std::abs(Dot(wi, h.ns));
    if (f.IsZero()) return std::nullopt;
    float w = 1;
    if (ls->pdf > 0 && continuation != nullptr)
        w = PowerHeuristic(ls->pdf, continuation->Pdf(wo, wi, r.lambda));
    RayRecord s = r;
    s.kind = kShadowRay;
    s.origin = LeaveSurface(s, h, wi, Length(h.p - r.origin), /*scattered=*/false);
    // As wide as the light: its shadows blur over as much (Light::ShadowSpread).
    s.cone_spread = std::max(s.cone_spread, light.ShadowSpread());
    s.dir = wi;
    s.t_max = ls->t_max;
    s.beta = r.beta * f * ls->weight * w;
    return s;
}

std::optional<RayRecord> LightSampler::SampleSky(const SurfaceHit& h, const Bsdf& bsdf,
                                                 const Vec3f& wo, const RayRecord& r,
                                                 const VertexRng& rng,
                                                 const GuidedBsdf* continuation) const {
    const int side = PathGuide::SideSeenFrom(h.ns, wo);
    const std::optional<Vec3f> sampled = SampleSkyDirection(h.p, side, rng);
    if (!sampled) return std::nullopt;
    const Vec3f& wi = *sampled;
    SampledSpectrum f = bsdf.Eval(wo, wi, r.lambda) * std::abs(Dot(wi, h.ns));
    if (f.IsZero()) return std::nullopt;
    const float light_pdf = SkyPdf(h.p, side, wi);
    if (!(light_pdf > 0)) return std::nullopt;
    float w = continuation != nullptr
                  ? PowerHeuristic(light_pdf, continuation->Pdf(wo, wi, r.lambda))
                  : 1.f;
    RayRecord s = r;
    s.kind = kShadowRay;
    // One direction of the sky seen through the windows, a cone of sky as wide as a diffuse
    // bounce's lobe or more: its footprint widens as a scattered ray's (kScatteredConeSpread).
    s.origin = LeaveSurface(s, h, wi, Length(h.p - r.origin), /*scattered=*/true);
    s.dir = wi;
    s.t_max = kInfinity;
    const SampledSpectrum radiance = scene_.sky->Radiance(wi, r.lambda);
    s.beta = r.beta * f * radiance * (w / light_pdf);
    if (s.beta.IsZero()) return std::nullopt;
    if (windows_ != nullptr) {
        // The ray teaches the windows if it reaches the sky: what LearnFromSkyShadow turns the
        // contribution into, once the panes on the way have dimmed it, is radiance x |cos θ| /
        // pdf, without the throughput, the BSDF or the MIS weight.
        s.flags = uint8_t(r.flags | kSkyShadow);
        s.guide_side = uint8_t(side);
        s.window_estimate_scale =
            radiance.Average() * std::abs(Dot(wi, h.ns)) / (light_pdf * s.beta.Average());
    }
    return s;
}

std::optional<Vec3f> LightSampler::SampleSkyDirection(const Vec3f& p, int side,
                                                      const VertexRng& rng) const {
    const uint32_t dim = kDimLight0 + 2 * uint32_t(scene_.lights.size());
    const SkyWindows::Region* region = windows_ ? windows_->Find(p, side) : nullptr;
    // With a learned region, kLearnedSkyShare of the samples from it and the rest split as
    // without: u_strategy below kLearnedSkyShare picks a learned window, above it is rescaled.
    float u_strategy = rng.Uniform(dim + 2);
    const Point2f u(rng.Uniform(dim), rng.Uniform(dim + 1));
    std::optional<Vec3f> on_window;  // the point aimed at, when a window was chosen
    if (region != nullptr && u_strategy < kLearnedSkyShare) {
        on_window = windows_->SamplePoint(*region, rng.Uniform(dim + 3), u);
    } else {
        if (region != nullptr)
            u_strategy = (u_strategy - kLearnedSkyShare) / (1 - kLearnedSkyShare);
        if (portals_ != nullptr && u_strategy < kPortalSkyShare)
            on_window = portals_->SamplePoint(rng.Uniform(dim + 3), u);
    }
    if (on_window) {
        const float d = Length(*on_window - p);
        if (!(d > 0)) return std::nullopt;
        return (*on_window - p) / d;
    }
    return SkyLight::SampleUniform(u);
}

std::optional<RayRecord> LightSampler::SampleLightInMedium(const Light& light, int index,
                                                           const Vec3f& p,
                                                           const HenyeyGreenstein& phase,
                                                           const RayRecord& r,
                                                           const VertexRng& rng) const {
    Point2f u(rng.Uniform(kDimLight0 + 2 * index), rng.Uniform(kDimLight0 + 2 * index + 1));
    const std::optional<LightSample> ls = light.SampleLi(p, u, r.lambda);
    if (!ls || ls->weight.IsZero()) return std::nullopt;
    const float f = phase.Eval(Dot(r.dir, ls->wi));
    const float w = ls->pdf > 0 ? PowerHeuristic(ls->pdf, f) : 1.f;
    RayRecord s = ShadowFromMedium(r, p, ls->wi, ls->t_max);
    s.cone_spread = std::max(s.cone_spread, light.ShadowSpread());
    s.beta = r.beta * ls->weight * (f * w);
    return s;
}

std::optional<RayRecord> LightSampler::SampleSkyInMedium(const Vec3f& p,
                                                         const HenyeyGreenstein& phase,
                                                         const RayRecord& r,
                                                         const VertexRng& rng) const {
    // Side 0: a medium's vertex has none; the learned windows (photon mode) are not used there.
    const std::optional<Vec3f> sampled = SampleSkyDirection(p, 0, rng);
    if (!sampled) return std::nullopt;
    const Vec3f& wi = *sampled;
    const float light_pdf = SkyPdf(p, 0, wi);
    if (!(light_pdf > 0)) return std::nullopt;
    const float f = phase.Eval(Dot(r.dir, wi));
    const float w = PowerHeuristic(light_pdf, f);
    RayRecord s = ShadowFromMedium(r, p, wi, kInfinity);
    s.cone_spread = std::max(s.cone_spread, kScatteredConeSpread);
    s.beta = r.beta * scene_.sky->Radiance(wi, r.lambda) * (f * w / light_pdf);
    if (s.beta.IsZero()) return std::nullopt;
    return s;
}

RayRecord LightSampler::ShadowFromMedium(const RayRecord& r, const Vec3f& p, const Vec3f& wi,
                                         float t_max) {
    RayRecord s = r;
    s.kind = kShadowRay;
    s.flags = uint8_t(r.flags & ~kSkyShadow);
    s.cone_width = ConeWidthAt(r, r.t_max);
    s.origin_level = 0;
    s.level_reach = 0;
    s.origin = p;
    s.since_vertex = 0;
    s.dir = wi;
    s.t_max = t_max;
    s.t_enter = s.t_exit = 0;
    s.guide_credit = PathGuide::kNoCredit;
    return s;
}

void LightSampler::LearnFromSkyShadow(const RayRecord& shadow) const {
    // A contribution so small that its factor overflowed teaches nothing worth its risk.
    if (windows_ == nullptr || !(shadow.window_estimate_scale > 0) ||
        !std::isfinite(shadow.window_estimate_scale))
        return;
    const std::optional<BrickHit> window = portals_->FirstCrossing(shadow.origin, shadow.dir);
    if (!window) return;  // a uniform direction that no window lets in
    windows_->RecordEstimate(shadow.origin, shadow.guide_side, window->triangle,
                             double(shadow.beta.Average()) * double(shadow.window_estimate_scale));
}

float LightSampler::SkyPdf(const Vec3f& p, int side, const Vec3f& w) const {
    if (portals_ == nullptr) return SkyLight::UniformPdf();
    const SkyWindows::Region* region = windows_ ? windows_->Find(p, side) : nullptr;
    double portal_pdf = 0, learned_pdf = 0;
    portals_->ForEachCrossing(p, w, kInfinity, [&](const BrickHit& hit) {
        const float cos_theta = std::abs(Dot(Normalize(hit.ng), w));
        if (cos_theta > 1e-6f) {
            // Area to solid angle: d² / |cos θ| (Veach 1997 §9.2).
            const double to_solid_angle = double(hit.t) * hit.t / double(cos_theta);
            portal_pdf += to_solid_angle / portals_->area();
            if (region != nullptr)
                learned_pdf += to_solid_angle * windows_->AreaDensity(*region, hit.triangle);
        }
    });
    const double unlearned =
        (1 - kPortalSkyShare) * SkyLight::UniformPdf() + kPortalSkyShare * portal_pdf;
    if (region == nullptr) return float(unlearned);
    return float(kLearnedSkyShare * learned_pdf + (1 - kLearnedSkyShare) * unlearned);
}

}  // namespace nave::render
