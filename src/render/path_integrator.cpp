#include "src/render/path_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <optional>

#include "src/core/byte_stream.h"
#include "src/core/image_error.h"
#include "src/core/log.h"
#include "src/core/progress.h"
#include "src/core/sampling.h"
#include "src/render/brick_walk.h"
#include "src/render/rng.h"
#include "src/render/sppm.h"
#include "src/render/stopping_rule.h"
#include "src/render/surface_hit.h"
#include "src/render/transport_common.h"

namespace nave::render {

PathIntegrator::PathIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                               const LightSampler& lights, VisiblePoints* visible_points)
    : scene_(scene),
      film_(film),
      scheduler_(scheduler),
      lights_(lights),
      visible_points_(visible_points),
      has_thin_glass_(
          std::any_of(scene.materials.begin(), scene.materials.end(),
                      [](const SurfaceMaterial& m) { return m.thin_glass() != nullptr; })) {
    if (visible_points == nullptr && scene.settings.path_guiding &&
        !scene.source->bounds().Empty()) {
        guide_ = std::make_unique<PathGuide>(scene.source->bounds(), kGuideCoarseCellsLongAxis,
                                             kGuideMaxCells, GuideRadianceScale());
    }
}

double PathIntegrator::GuideRadianceScale() const {
    // The radiance of a white surface in full sun (or, without a sun, the sky's brightest axis):
    // the order of the light that surfaces reflect toward the paths' vertices.
    const SampledWavelengths green = SampledWavelengths::SampleVisible(0.5f);
    double scale = 0;
    if (scene_.sun >= 0) {
        const Light& sun = scene_.lights[size_t(scene_.sun)];
        const double solid_angle = sun.SunSolidAngle();
        scale = double(sun.spectrum.Sample(green).Average()) * solid_angle * kInvPi;
    }
    if (scene_.sky) {
        for (const Vec3f& w : {Vec3f(1, 0, 0), Vec3f(-1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, -1, 0),
                               Vec3f(0, 0, 1), Vec3f(0, 0, -1)})
            scale = std::max(scale, double(scene_.SkyRadiance(w, green).Average()));
    }
    return scale > 0 ? scale : 1.0;
}

Status PathIntegrator::Run(RenderStats* stats, RenderSession* session) {
    const Camera& camera = *scene_.camera;
    const uint64_t pixels = uint64_t(camera.width()) * camera.height();
    const int spp = scene_.settings.spp;
    const uint64_t wave = scene_.settings.wave_paths;
    RenderSession one_run(nullptr, film_);
    if (session == nullptr) session = &one_run;
    const int start = session->start();
    NAVE_RETURN_IF_ERROR(session->RestoreFilm());
    if (guide_ && session->resume() != nullptr) {
        NAVE_ASSIGN_OR_RETURN(std::string_view bytes, session->Section("path_guide"));
        ByteReader in(bytes, session->resume_name() + " section path_guide");
        NAVE_RETURN_IF_ERROR(guide_->LoadState(&in));
        NAVE_RETURN_IF_ERROR(in.ExpectEnd());
    }
    session->ReleaseResumed();
    // Advanced by every path as it ends, on the workers: a wave can be the whole image.
    ProgressBar progress("render", pixels * uint64_t(std::max(spp, start)), "paths");
    progress.Add(pixels * uint64_t(start));
    progress_ = &progress;
    struct Unset {
        ProgressBar*& bar;
        ~Unset() { bar = nullptr; }
    } unset{progress_};  // before `progress` goes, whichever way Run returns
    StoppingRule stop(scene_.settings, &progress, session->elapsed_before_s());
    int passes = start;
    // Small images put several passes in one wave, so that the streams stay long enough to keep
    // every thread busy; large images split a pass into waves to bound the memory of the queues.
    // A render that may be checkpointed ends every pass with a complete drain instead: its state
    // is then the film and the guide alone, and the order in which the film adds up its samples
    // does not depend on when checkpoints were written.
    const int passes_per_wave =
        session->active() ? 1 : int(std::clamp<uint64_t>(wave / pixels, 1, uint64_t(spp)));
    // With a noise target or a time limit, a wave stops for a check at least every quarter of the
    // passes done so far (2, 3, 4, 5, ... 8, 10, 12, 15...): at most ~25 % more passes than needed.
    const bool checks = scene_.settings.noise_target > 0 || scene_.settings.time_limit_s > 0;
    for (int s = start; s < spp;) {
        const int group =
            checks ? std::min(passes_per_wave, std::max(s == 0 ? 2 : 1, s / 4)) : passes_per_wave;
        int s_end = std::min(spp, s + group);
        // The guide learns from every pass and updates its distributions after passes 1, 2, 4,
        // 8...: each update follows a complete drain, so that what it learned from does not depend
        // on the waves, the memory budget or the threads.
        const int next_update = guide_ ? int(std::bit_floor(unsigned(s))) * 2 + (s == 0) : 0;
        const bool update = guide_ && s_end >= next_update;
        if (update) s_end = next_update;
        for (uint64_t first = 0; first < pixels; first += wave) {
            const uint64_t last = std::min(pixels, first + wave);
            for (int k = s; k < s_end; ++k)
                NAVE_RETURN_IF_ERROR(GenerateCameraRays(first, last, uint32_t(k), nullptr));
            NAVE_RETURN_IF_ERROR(scheduler_.Drain(*this, scheduler_.WaveOverlap()));
        }
        if (update || session->active()) NAVE_RETURN_IF_ERROR(scheduler_.Drain(*this));
        if (update) {
            guide_->Update();
            log::Debug("path guide after {} passes: {} cells learning, {} guiding", s_end,
                       guide_->cells_used(), guide_->cells_guiding());
        }
        passes = s_end;
        s = s_end;
        // The last wave's tail may still be in flight: the estimate misses a little of the last
        // pass, which the final estimate, after the last drain, does not.
        const bool enough = stop.ShouldStop([&] { return NoiseEstimate(passes); });
        bool end_run = false;
        NAVE_RETURN_IF_ERROR(session->AtBoundary(
            passes, stop.Elapsed(), enough || passes >= spp,
            [&](Checkpoint* checkpoint) {
                if (!guide_) return;
                ByteWriter out;
                guide_->SaveState(&out);
                checkpoint->sections["path_guide"] = out.Take();
            },
            &end_run));
        if (enough || end_run) break;
    }
    NAVE_RETURN_IF_ERROR(scheduler_.Drain(*this));  // the last wave's tail
    progress.Finish();
    stats->samples_per_pixel = passes;
    stats->noise_relmse = NoiseEstimate(passes);
    if (guide_) {
        stats->guide_cells = guide_->cells_used();
        stats->guide_cells_guiding = guide_->cells_guiding();
    }
    stats->camera_paths = pixels * uint64_t(passes);
    film_->SetSamplesPerPixel(passes);
    return Status::Ok();
}

double PathIntegrator::NoiseEstimate(int passes) const {
    if (passes < 2) return std::nan("");
    return HalvesRelMse(film_->pixel_count(), [&](size_t p) {
        return std::array<double, 2>{film_->HalfLuminance(uint32_t(p), 0, passes),
                                     film_->HalfLuminance(uint32_t(p), 1, passes)};
    });
}

Status PathIntegrator::GenerateCameraRays(uint64_t first, uint64_t last, uint32_t sample,
                                          const SampledWavelengths* lambda) {
    // In chunks, with the queues spilled beyond their cap between two: a wave may be larger than
    // the queues' memory (under a budget the whole image is one wave, docs/pager.md).
    const uint64_t chunk = scheduler_.generate_chunk();
    for (uint64_t begin = first; begin < last; begin += chunk) {
        GenerateCameraChunk(begin, std::min(last, begin + chunk), sample, lambda);
        NAVE_RETURN_IF_ERROR(scheduler_.SpillIfOverCap());
    }
    return Status::Ok();
}

void PathIntegrator::GenerateCameraChunk(uint64_t first, uint64_t last, uint32_t sample,
                                         const SampledWavelengths* lambda) {
    const Camera& camera = *scene_.camera;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, last, 1024), [&](const auto& range) {
        RayOutbox out;
        for (uint64_t p = range.begin(); p != range.end(); ++p) {
            RayRecord r{};
            r.kind = kPathRay;
            r.pixel = uint32_t(p);
            r.sample = sample;
            VertexRng rng(RayKey(scene_.settings.seed, r, iteration_, kStreamCamera));
            float x = float(p % uint64_t(camera.width())) + rng.Uniform(kDimPixelX);
            float y = float(p / uint64_t(camera.width())) + rng.Uniform(kDimPixelY);
            camera.GenerateRay(x, y, rng.Uniform(kDimLens0), rng.Uniform(kDimLens1), &r.origin,
                               &r.dir);
            r.lambda =
                lambda ? *lambda : SampledWavelengths::SampleVisible(rng.Uniform(kDimLambda));
            r.beta = SampledSpectrum(1.f);
            r.t_max = kInfinity;
            Spawn(r, store::kNoBrick, nullptr, out);
        }
        scheduler_.Flush(out);
    });
}

void PathIntegrator::ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                                  std::span<const RayRecord> rays, RayOutbox& out) {
    for (const RayRecord& r : rays) ProcessRay(r, brick, resident, out);
}

void PathIntegrator::ProcessRay(RayRecord r, uint32_t b, const ResidentBrick& brick,
                                RayOutbox& out) {
    if (r.kind == kShadowRay) {
        const float t1 = std::min(SegmentEndWithSlack(r.t_exit), r.t_max);
        if (!ShadowThroughBrick(r, brick, t1, out.counts)) return;
        const uint32_t next = scheduler_.Route(r, r.t_exit, b);
        if (next == store::kNoBrick) {
            AddShadowContribution(r);  // unoccluded all the way
        } else {
            out.Send(next, b, r);
        }
        return;
    }
    TraceInBrick(
        r, b, brick, scheduler_, out,
        [&](RayRecord& path, const BrickHit& hit) {
            const bool goes_on = ShadePath(path, b, brick, hit, out);
            if (!goes_on && progress_ != nullptr) progress_->Add(1);
            return goes_on;
        },
        [&](const RayRecord& path) { Escape(path); });
}

void PathIntegrator::Escape(const RayRecord& r) {
    if (progress_ != nullptr) progress_->Add(1);  // the path ends here
    SampledSpectrum L;
    if (scene_.sky) {
        // The sky is also next-event estimated: weight the BSDF-sampled escape against it, at the
        // vertex the direction was sampled from.
        float w = 1;
        if (r.depth > 0 && !(r.flags & kSpecularBounce)) {
            w = PowerHeuristic(r.prev_pdf,
                               lights_.SkyPdf(r.origin - r.dir * r.since_vertex, r.dir));
        }
        const SampledSpectrum sky = scene_.SkyRadiance(r.dir, r.lambda);
        L += sky * w;
        // The sky seen through a window from the last vertex: the guide learns where windows are
        // open to it, which next-event estimation, aiming at all windows alike, does not know.
        if (guide_ && r.depth > 0 && !(r.flags & kSpecularBounce) && r.prev_pdf > 0) {
            guide_->Credit(
                guide_->CreditKey(r.origin - r.dir * r.since_vertex, r.guide_side, r.dir),
                double(sky.Average()) / double(r.prev_pdf));
        }
    }
    if (scene_.sun >= 0) {
        const Light& sun = scene_.lights[size_t(scene_.sun)];
        if (sun.SeesSun(r.dir)) {
            // A BSDF-sampled direction that found the sun: weighted against next-event estimation
            // of the sun (power heuristic). Camera rays and specular bounces cannot be
            // light-sampled: weight 1.
            float w = 1;
            if (r.depth > 0 && !(r.flags & kSpecularBounce)) {
                w = PowerHeuristic(r.prev_pdf, sun.SunPdf());
            }
            L += sun.spectrum.Sample(r.lambda) * w;
        }
    }
    if (!L.IsZero()) film_->AddSample(r.pixel, r.beta * L, r.lambda, Half(r));
}

void PathIntegrator::AddShadowContribution(const RayRecord& r) {
    film_->AddSample(r.pixel, r.beta, r.lambda, Half(r));
    if (guide_ && r.guide_credit != PathGuide::kNoCredit)
        guide_->Credit(r.guide_credit, double(r.beta.Average()) * double(r.guide_scale));
}

bool PathIntegrator::ShadowThroughBrick(RayRecord& r, const ResidentBrick& brick, float t1,
                                        RayCounts& c) const {
    float t0 = r.t_enter;
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

void PathIntegrator::Spawn(RayRecord r, uint32_t b, const ResidentBrick* brick, RayOutbox& out) {
    ++out.counts.rays;
    uint32_t next = scheduler_.Route(r, 0, store::kNoBrick);
    if (next == store::kNoBrick) {
        if (r.kind == kShadowRay) {
            AddShadowContribution(r);
        } else {
            Escape(r);
        }
        return;
    }
    if (next == b && brick != nullptr && r.kind == kShadowRay) {
        ProcessRay(r, b, *brick, out);  // same brick, resident now: no need to queue
        return;
    }
    out.Send(next, b, r);
}

bool PathIntegrator::ShadePath(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                               const BrickHit& hit, RayOutbox& out) {
    SurfaceHit h = MakeSurfaceHit(scene_, brick, hit, r.dir);
    const SurfaceMaterial& mat = *h.material;
    const Vec3f wo = -r.dir;
    AbsorbInsideGlass(mat, h, &r);
    if (r.depth == 0) film_->AddAov(r.pixel, Vec3f(1, 1, 1) * mat.AlbedoForAov(), h.ns, hit.t);
    if (mat.emissive) {
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
    if (visible_points_ != nullptr && mat.dispersive() && !r.lambda.SecondaryTerminated() &&
        r.beta.MaxValue() == r.beta.MinValue()) {
        // Photon mode: the path is about to keep one wavelength. Nothing it did so far depended on
        // its own (the throughput is the same at all four), so it may take its iteration's shared
        // wavelengths instead, which some photons carry too (sppm.h).
        r.lambda = IterationWavelengths(uint64_t(scene_.settings.seed), iteration_,
                                        VisiblePoints::PixelChannel(r.pixel));
    }
    Bsdf bsdf = mat.MakeBsdf(h.ns, &r.lambda, h.has_uv ? &h.uv : nullptr, h.footprint);
    const uint8_t flags = bsdf.Flags();
    if (flags == kBxdfUnset) return false;
    VertexRng rng(RayKey(scene_.settings.seed, r, iteration_, kStreamPath));
    const bool non_specular = flags & (kBxdfDiffuse | kBxdfGlossy);
    // In photon mode the path stops at its first diffuse vertex: no BSDF-sampled direction will
    // find the lights from here, so next-event estimation takes the full weight.
    const bool visible_point =
        scene_.settings.mode == RenderSettings::Mode::kPhoton && (flags & kBxdfDiffuse);
    // The side the path sees of the surface, which keeps the guide's histograms of a floor and
    // of the wall above it apart.
    const int side = PathGuide::SideOf(Dot(h.ns, wo) >= 0 ? h.ns : -h.ns);
    const GuidedBsdf continuation(bsdf, guide_.get(), h.p, side);
    if (non_specular) {
        // What next-event estimation finds here, reflected once more, is light arriving at the
        // path's previous vertex from this one: its shadow rays credit the guide there.
        uint32_t credit = PathGuide::kNoCredit;
        float credit_scale = 0;
        const float beta = r.beta.Average();
        if (guide_ && r.depth > 0 && !(r.flags & kSpecularBounce) && beta > 0 && r.prev_pdf > 0) {
            credit = guide_->CreditKey(r.origin - r.dir * r.since_vertex, r.guide_side, r.dir);
            credit_scale = 1 / (beta * r.prev_pdf);
        }
        const GuidedBsdf* mis_against = visible_point ? nullptr : &continuation;
        auto spawn_shadow = [&](std::optional<RayRecord> shadow) {
            if (!shadow) return;
            shadow->guide_credit = credit;
            shadow->guide_scale = credit_scale;
            Spawn(*shadow, b, &brick, out);
        };
        for (size_t i = 0; i < scene_.lights.size(); ++i) {
            spawn_shadow(
                lights_.SampleLight(scene_.lights[i], int(i), h, bsdf, wo, r, rng, mis_against));
        }
        // With render.sky_direct = "photons", the sky's photons bring its direct light to the
        // visible points.
        const bool sky_from_photons =
            visible_point && scene_.settings.sky_direct == RenderSettings::SkyDirect::kPhotons;
        if (scene_.sky && !sky_from_photons)
            spawn_shadow(lights_.SampleSky(h, bsdf, wo, r, rng, mis_against));
    }
    if (visible_point) {
        // SPPM: the path stops at its first diffuse vertex; indirect light there comes from
        // photons.
        visible_points_->Add(r.pixel, h.p, h.ns, wo, mat, h.has_uv ? &h.uv : nullptr, h.footprint,
                             r.beta, r.lambda);
        return false;
    }
    std::optional<BsdfSample> bs = continuation.Sample(
        wo, rng.Uniform(kDimGuideChoice), rng.Uniform(kDimBsdfChoice),
        Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)),
        {rng.Uniform(kDimGuideBin), rng.Uniform(kDimGuide0), rng.Uniform(kDimGuide1)}, r.lambda);
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
    r.guide_side = uint8_t(side);
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

}  // namespace nave::render
