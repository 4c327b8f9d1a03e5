#include "src/render/integrators/camera_paths.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "src/core/progress.h"
#include "src/render/bricks/brick_walk.h"
#include "src/render/transport/medium_flight.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {

CameraPaths::CameraPaths(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                         const LightSampler& lights, PathGuide* guide)
    : scene_(scene),
      film_(film),
      scheduler_(scheduler),
      lights_(lights),
      guide_(guide),
      has_thin_glass_(
          std::any_of(scene.materials.begin(), scene.materials.end(),
                      [](const SurfaceMaterial& m) { return m.thin_glass() != nullptr; })) {}

Status CameraPaths::GenerateCameraRays(uint64_t first, uint64_t last, uint32_t sample) {
    // In chunks, with the queues spilled beyond their cap between two: a wave may be larger than
    // the queues' memory (under a budget the whole image is one wave, docs/pager.md).
    const uint64_t chunk = scheduler_.generate_chunk();
    for (uint64_t begin = first; begin < last; begin += chunk) {
        GenerateCameraChunk(begin, std::min(last, begin + chunk), sample);
        NAVE_RETURN_IF_ERROR(scheduler_.SpillIfOverCap());
    }
    return Status::Ok();
}

void CameraPaths::GenerateCameraChunk(uint64_t first, uint64_t last, uint32_t sample) {
    const Camera& camera = *scene_.camera;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, last, 1024), [&](const auto& range) {
        RayOutbox out;
        for (uint64_t p = range.begin(); p != range.end(); ++p) {
            RayRecord r{};
            r.kind = kPathRay;
            r.pixel = uint32_t(p);
            r.sample = sample;
            VertexRng rng(RayKey(scene_.settings.seed, r, iteration_, kStreamCamera));
            const uint64_t column = p % uint64_t(camera.width()),
                           row = p / uint64_t(camera.width());
            float x = float(column) + rng.Uniform(kDimPixelX);
            float y = float(row) + rng.Uniform(kDimPixelY);
            camera.GenerateRay(x, y, rng.Uniform(kDimLens0), rng.Uniform(kDimLens1), &r.origin,
                               &r.dir);
            r.lambda = SampledWavelengths::SampleVisible(rng.Uniform(kDimLambda));
            r.beta = SampledSpectrum(1.f);
            r.t_max = kInfinity;
            // A pinhole's cone: no width at the camera, one pixel's angle of spread.
            r.cone_spread = camera.PixelSpreadAngle();
            // In a distributed render the process owning the ray's first brick makes it.
            if (!scheduler_.MakesHere(r, p)) continue;
            Spawn(r, store::kNoBrick, nullptr, out);
        }
        scheduler_.Flush(out);
    });
}

void CameraPaths::ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                               std::span<const RayRecord> rays, RayOutbox& out) {
    for (const RayRecord& r : rays) ProcessRay(r, brick, resident, out);
}

void CameraPaths::ProcessRay(RayRecord r, uint32_t b, const ResidentBrick& brick, RayOutbox& out) {
    if (r.kind == kShadowRay) {
        const float t0 = r.t_enter, t1 = SegmentEnd(r, brick);
        if (!ShadowThroughBrick(r, brick, t1, out.counts)) return;
        const uint32_t next = scheduler_.Route(r, r.t_exit, b);
        // What the medium lets through from here to the next brick (or the light).
        if (!DimShadowRay(scene_.MediumOf(r.medium), &brick, t0,
                          next == store::kNoBrick ? r.t_max : r.t_enter, &r))
            return;
        if (next == store::kNoBrick) {
            AddShadowContribution(r);  // unoccluded all the way
        } else {
            out.Send(next, b, r);
        }
        return;
    }
    TraceInBrick(
        r, b, brick, scheduler_, out,
        [&](RayRecord& path, float t0, float t1) { return FlyTo(path, t0, t1, b, &brick, out); },
        [&](RayRecord& path, const BrickHit& hit) {
            EndFlightAtSurface(scene_.MediumOf(path.medium), &path);
            const bool goes_on = ShadePath(path, b, brick, hit, out);
            if (!goes_on && progress_ != nullptr) progress_->Add(1);
            return goes_on;
        },
        [&](const RayRecord& path) { LeaveModel(path); });
}

namespace {

/// Russian roulette (Arvo & Kirk 1990) past the second bounce, once the throughput is below 1:
/// false if path `r` ends here, else its throughput is raised by the survival probability.
bool SurvivesRoulette(RayRecord& r, const VertexRng& rng) {
    if (r.depth < 2) return true;
    const float m = r.beta.MaxValue();
    if (m >= 1) return true;
    const float q = std::max(0.f, 1 - m);
    if (rng.Uniform(kDimRoulette) < q) return false;
    r.beta /= 1 - q;
    return true;
}

}  // namespace

float CameraPaths::PathFlightDepth(const RayRecord& r) const {
    // Keyed to the path's vertex, which does not change along the ray's flight: every brick the
    // ray crosses draws the same numbers.
    const VertexRng rng(RayKey(scene_.settings.seed, r, iteration(), kStreamPath));
    return FlightDepth(*scene_.MediumOf(r.medium), r.lambda, rng.Uniform(kDimFlightChoice),
                       rng.Uniform(kDimFlightDistance));
}

bool CameraPaths::FlyTo(RayRecord& r, float t0, float t1, uint32_t b, const ResidentBrick* brick,
                        RayOutbox& out) {
    const Medium* medium = scene_.MediumOf(r.medium);
    if (medium == nullptr) return true;
    const DensityField* field = medium->DensityIn(brick);
    if (field == nullptr || !(t1 > t0)) return true;
    const float depth = PathFlightDepth(r);
    const float depth0 = r.flight_depth;
    const float t = Fly(field, depth, t0, t1, &r);
    if (medium->emission() != nullptr)
        AddMediumEmission(r, *medium, *field, depth0, t0, std::min(t, t1));
    if (!(t < kInfinity)) return true;
    ScatterInMedium(r, t, depth, b, brick, out);
    return false;
}

void CameraPaths::AddMediumEmission(const RayRecord& r, const Medium& medium,
                                    const DensityField& field, float depth0, float t0, float t1) {
    // Keyed as the flight is: every brick the ray crosses looks at the same fraction of its voxels.
    const VertexRng rng(RayKey(scene_.settings.seed, r, iteration(), kStreamPath));
    const SampledSpectrum L =
        EmissionAlong(medium, field, r, depth0, t0, t1, rng.Uniform(kDimEmissionPoint));
    if (!L.IsZero()) film_->AddSample(r.pixel, r.beta * L, r.lambda, Half(r));
}

void CameraPaths::LeaveModel(RayRecord r) {
    if (const Medium* medium = scene_.MediumOf(r.medium))
        r.beta *= NoScatterWeight(*medium, r.lambda, r.flight_depth);
    Escape(r);
}

void CameraPaths::ScatterInMedium(RayRecord r, float t, float depth, uint32_t b,
                                  const ResidentBrick* brick, RayOutbox& out) {
    const Medium& medium = *scene_.MediumOf(r.medium);
    const Vec3f p = r.origin + r.dir * t;
    r.t_max = t;  // the ray ends at its vertex (the light sampler's cones start there)
    r.beta *= ScatterWeight(medium, r.lambda, depth);
    r.flags &= uint8_t(~kSkyShadow);
    // As at surfaces (ShadePath): a vertex at max_depth ends the path before it estimates light.
    const auto path_ends = [&] {
        if (progress_ != nullptr) progress_->Add(1);
    };
    if (r.depth >= uint32_t(scene_.settings.max_depth) || r.beta.IsZero()) return path_ends();
    const VertexRng rng(RayKey(scene_.settings.seed, r, iteration(), kStreamPath));
    // Next-event estimation from the medium's vertex, weighted against sampling the phase
    // function, which is how the path goes on.
    for (size_t i = 0; i < scene_.lights.size(); ++i) {
        if (std::optional<RayRecord> shadow =
                lights_.SampleLightInMedium(*scene_.lights[i], int(i), p, medium.phase(), r, rng))
            Spawn(*shadow, b, brick, out);
    }
    if (scene_.sky) {
        if (std::optional<RayRecord> shadow = lights_.SampleSkyInMedium(p, medium.phase(), r, rng))
            Spawn(*shadow, b, brick, out);
    }
    // The phase function is sampled exactly: the throughput keeps its value.
    const PhaseSample ps =
        medium.phase().Sample(r.dir, Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)));
    if (!SurvivesRoulette(r, rng)) return path_ends();
    r.guide_side = kMediumSide;
    r.prev_pdf = ps.pdf;
    // Photon mode's gathering paths: a scattering is no specular bounce (CausticFromPhotons).
    if (r.flags & kGathering) r.flags = ExtendSpecularChain(r.flags, false);
    LeaveMediumVertex(&r, t, ps.wi);
    Spawn(r, b, brick, out);
}

void CameraPaths::Escape(const RayRecord& r) {
    if (progress_ != nullptr) progress_->Add(1);  // the path ends here
    if (CausticFromPhotons(r)) return;
    SampledSpectrum L;
    if (scene_.sky) {
        // The sky is also next-event estimated: weight the BSDF-sampled escape against it, at the
        // vertex the direction was sampled from.
        float w = 1;
        if (r.depth > 0 && !(r.flags & kSpecularBounce)) {
            const int side = r.guide_side == kMediumSide ? 0 : r.guide_side;
            w = PowerHeuristic(r.prev_pdf,
                               lights_.SkyPdf(r.origin - r.dir * r.since_vertex, side, r.dir));
        }
        const SampledSpectrum sky = scene_.sky->Radiance(r.dir, r.lambda);
        L += sky * w;
        // The sky seen through a window from the last vertex: the guide learns where windows are
        // open to it, which next-event estimation, aiming at all windows alike, does not know.
        if (guide_ != nullptr && r.depth > 0 && !(r.flags & kSpecularBounce) && r.prev_pdf > 0 &&
            r.guide_side != kMediumSide) {
            guide_->Credit(
                guide_->CreditKey(r.origin - r.dir * r.since_vertex, r.guide_side, r.dir),
                double(sky.Average()) / double(r.prev_pdf), r.sample);
        }
    }
    if (scene_.sun >= 0) {
        const SunLight& sun = scene_.sun_light();
        if (sun.Sees(r.dir)) {
            // A BSDF-sampled direction that found the sun: weighted against next-event estimation
            // of the sun (power heuristic). Camera rays and specular bounces cannot be
            // light-sampled: weight 1.
            float w = 1;
            if (r.depth > 0 && !(r.flags & kSpecularBounce)) {
                w = PowerHeuristic(r.prev_pdf, sun.Pdf());
            }
            L += sun.radiance().Sample(r.lambda) * w;
        }
    }
    if (!L.IsZero()) film_->AddSample(r.pixel, r.beta * L, r.lambda, Half(r));
}

void CameraPaths::AddShadowContribution(const RayRecord& r) {
    film_->AddSample(r.pixel, r.beta, r.lambda, Half(r));
    if (r.flags & kSkyShadow) lights_.LearnFromSkyShadow(r);
    if (guide_ != nullptr && r.guide_credit != PathGuide::kNoCredit)
        guide_->Credit(r.guide_credit, double(r.beta.Average()) * double(r.guide_scale), r.sample);
}

bool CameraPaths::ShadowThroughBrick(RayRecord& r, const ResidentBrick& brick, float t1,
                                     RayCounts& c) const {
    float t0 = SegmentStart(r, brick);
    for (;;) {
        ++c.shadow_segments;
        if (!has_thin_glass_) return !brick.Occluded(r.origin, r.dir, t0, t1);
        BrickHit hit;
        if (!brick.Intersect(r.origin, r.dir, t0, t1, &hit)) return true;
        SurfaceHit h = MakeSurfaceHit(scene_, brick, hit, r.dir);
        const SurfaceMaterial& m = *h.material;
        const ThinGlassMaterial* glass = m.thin_glass();
        if (glass == nullptr) return false;
        SampledSpectrum reflected, transmitted;
        ThinDielectricBxdf(glass->eta.Sample(r.lambda),
                           m.GlassInternalTransmittance(h.has_uv ? &h.uv : nullptr, r.lambda))
            .ReflectanceTransmittance(Dot(r.dir, h.ns), &reflected, &transmitted);
        r.beta *= transmitted;
        if (r.beta.IsZero()) return false;
        t0 = hit.t + 1e-5f * (1.f + std::abs(hit.t));  // past this pane
    }
}

void CameraPaths::Spawn(RayRecord r, uint32_t b, const ResidentBrick* brick, RayOutbox& out) {
    ++out.counts.rays;
    uint32_t next = scheduler_.Route(r, 0, store::kNoBrick);
    if (const Medium* medium = scene_.MediumOf(r.medium); medium != nullptr) {
        // The medium between the ray's origin and its first brick (outside every brick's cell:
        // only a field that holds everywhere has density there).
        const float t1 = next == store::kNoBrick ? r.t_max : r.t_enter;
        if (r.kind == kShadowRay) {
            if (!DimShadowRay(medium, brick, 0, t1, &r)) return;
        } else {
            r.flight_depth = 0;
            if (!FlyTo(r, 0, t1, b, brick, out)) return;
        }
    }
    if (next == store::kNoBrick) {
        if (r.kind == kShadowRay) {
            AddShadowContribution(r);
        } else {
            LeaveModel(r);
        }
        return;
    }
    if (next == b && brick != nullptr && r.kind == kShadowRay) {
        ProcessRay(r, b, *brick, out);  // same brick, resident now: no need to queue
        return;
    }
    out.Send(next, b, r);
}

bool CameraPaths::ShadePath(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                            const BrickHit& hit, RayOutbox& out) {
    SurfaceHit h = MakeSurfaceHit(scene_, brick, hit, r.dir);
    const SurfaceMaterial& mat = *h.material;
    AbsorbInsideGlass(mat, h, &r);
    if (r.depth == 0) film_->AddAov(r.pixel, Vec3f(1, 1, 1) * mat.AlbedoForAov(), h.ns, hit.t);
    if (mat.emissive && !CausticFromPhotons(r)) {
        // Emission found by the path itself (two-sided; emissive surfaces are not light-sampled, so
        // weight 1). In photon mode paths stop at their first diffuse vertex, so this only sees
        // specular and glossy chains; light reaching diffuse vertices from emitters comes with the
        // photons.
        film_->AddSample(r.pixel, r.beta * mat.Emitted(h.has_uv ? &h.uv : nullptr, r.lambda),
                         r.lambda, Half(r));
    }
    // A path at its last scattering still passes through thin glass (not a scattering event): cut
    // there, the light that next-event estimation left to BSDF sampling through a window would be
    // lost.
    const bool last = r.depth >= uint32_t(scene_.settings.max_depth);
    if (last && mat.thin_glass() == nullptr) return false;
    return ScatterAt(r, b, brick, h, last, out);
}

void CameraPaths::EstimateDirect(const RayRecord& r, uint32_t b, const ResidentBrick& brick,
                                 const SurfaceHit& h, const Bsdf& bsdf, const Vec3f& wo,
                                 const VertexRng& rng, const GuidedBsdf* mis_against, bool sky,
                                 uint32_t credit, float credit_scale, RayOutbox& out) {
    auto spawn_shadow = [&](std::optional<RayRecord> shadow) {
        if (!shadow) return;
        shadow->guide_credit = credit;
        shadow->guide_scale = credit_scale;
        Spawn(*shadow, b, &brick, out);
    };
    for (size_t i = 0; i < scene_.lights.size(); ++i) {
        spawn_shadow(
            lights_.SampleLight(*scene_.lights[i], int(i), h, bsdf, wo, r, rng, mis_against));
    }
    if (sky) spawn_shadow(lights_.SampleSky(h, bsdf, wo, r, rng, mis_against));
}

bool CameraPaths::Continue(RayRecord& r, const SurfaceHit& h, const GuidedBsdf& continuation,
                           const VertexRng& rng, int side, bool last) const {
    const Vec3f wo = -r.dir;
    std::optional<BsdfSample> bs = continuation.Sample(
        wo, rng.Uniform(kDimGuideChoice), rng.Uniform(kDimBsdfChoice),
        Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)),
        {rng.Uniform(kDimGuideBin), rng.Uniform(kDimGuide0), rng.Uniform(kDimGuide1)}, r.lambda);
    if (!bs) return false;
    r.beta *= bs->f * (std::abs(Dot(bs->wi, h.ns)) / bs->pdf);
    r.vertex += 1;
    if (IsPassThrough(*h.material, *bs)) return PassThrough(r, h, bs->wi);
    if (last) return false;
    r.flags = uint8_t((r.flags & ~kSpecularBounce) | (bs->IsSpecular() ? kSpecularBounce : 0));
    if (r.flags & kGathering)
        r.flags = ExtendSpecularChain(r.flags, bs->IsSpecular() && h.material->MakesCaustics());
    r.guide_side = uint8_t(side);
    r.prev_pdf = bs->pdf;
    if (!SurvivesRoulette(r, rng)) return false;
    return Bounce(r, h, bs->wi, bs->IsSpecular());
}

}  // namespace nave::render
