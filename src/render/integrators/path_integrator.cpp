#include "src/render/integrators/path_integrator.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "src/core/byte_stream.h"
#include "src/core/image_error.h"
#include "src/core/log.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {

StatusOr<std::unique_ptr<PathIntegrator>> PathIntegrator::Create(const RenderScene& scene,
                                                                 Film* film,
                                                                 StreamScheduler& scheduler) {
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<LightSampler> lights,
                          LightSampler::Create(scene, scheduler, nullptr));
    std::unique_ptr<PathGuide> guide;
    if (scene.settings.path_guiding && !scene.source->bounds().Empty()) {
        guide = std::make_unique<PathGuide>(scene.source->bounds(), kGuideCoarseCellsLongAxis,
                                            kGuideMaxCells, GuideRadianceScale(scene),
                                            GuideRounds::kDoublingPasses);
    }
    return std::unique_ptr<PathIntegrator>(
        new PathIntegrator(scene, film, scheduler, std::move(lights), std::move(guide)));
}

PathIntegrator::PathIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                               std::unique_ptr<LightSampler> lights,
                               std::unique_ptr<PathGuide> guide)
    : CameraPaths(scene, film, scheduler, *lights, guide.get()),
      owned_lights_(std::move(lights)),
      owned_guide_(std::move(guide)) {
    // A path's sample index is its pass: the guide's rounds wait for the rays of their passes.
    scheduler.CountRoundsOfPasses();
}

double PathIntegrator::GuideRadianceScale(const RenderScene& scene) {
    // The radiance of a white surface in full sun (or, without a sun, the sky's brightest axis):
    // the order of the light that surfaces reflect toward the paths' vertices.
    const SampledWavelengths green = SampledWavelengths::SampleVisible(0.5f);
    double scale = 0;
    if (scene.sun >= 0) {
        const SunLight& sun = scene.sun_light();
        const double solid_angle = sun.SolidAngle();
        scale = double(sun.radiance().Sample(green).Average()) * solid_angle * kInvPi;
    }
    if (scene.sky) scale = std::max(scale, scene.sky->BrightestAxisRadiance());
    return scale > 0 ? scale : 1.0;
}

ProgressUnits PathIntegrator::progress_units() const {
    // Advanced by every path as it ends, on the workers: a wave can be the whole image.
    return {"render", "paths", film_->pixel_count()};
}

Status PathIntegrator::Restore(const RenderSession& session) {
    if (!owned_guide_) return Status::Ok();
    NAVE_ASSIGN_OR_RETURN(std::string_view bytes, session.Section("path_guide"));
    ByteReader in(bytes, session.resume_name() + " section path_guide");
    NAVE_RETURN_IF_ERROR(owned_guide_->LoadState(&in));
    return in.ExpectEnd();
}

Status PathIntegrator::ShareState(RankGroup& ranks) {
    if (!owned_guide_) return Status::Ok();
    return owned_guide_->ShareCredits(
        [&](std::span<uint64_t> values) { return ranks.SumEverywhere(values); });
}

void PathIntegrator::Save(Checkpoint* checkpoint) const {
    if (!owned_guide_) return;
    ByteWriter out;
    owned_guide_->SaveState(&out);
    checkpoint->sections["path_guide"] = out.Take();
}

StatusOr<int> PathIntegrator::RenderRounds(int passes, bool boundaries) {
    const int s = passes;
    const uint64_t pixels = film_->pixel_count();
    const int spp = scene_.settings.spp;
    const uint64_t wave = scene_.settings.wave_paths;
    // Small images put several passes in one wave, so that the streams stay long enough to keep
    // every thread busy; large images split a pass into waves to bound the memory of the queues.
    // A render that may be checkpointed ends every pass with a complete drain instead: its state
    // is then the film and the guide alone, and the order in which the film adds up its samples
    // does not depend on when checkpoints were written.
    const int passes_per_wave =
        boundaries ? 1 : int(std::clamp<uint64_t>(wave / pixels, 1, uint64_t(spp)));
    // With a noise target or a time limit, a wave stops for a check at least every quarter of the
    // passes done so far (2, 3, 4, 5, ... 8, 10, 12, 15...): at most ~25 % more passes than needed.
    const bool checks = scene_.settings.noise_target > 0 || scene_.settings.time_limit_s > 0;
    const int group =
        checks ? std::min(passes_per_wave, std::max(s == 0 ? 2 : 1, s / 4)) : passes_per_wave;
    int s_end = std::min(spp, s + group);
    // The guide learns in rounds of passes (0-1 | 2-3 | 4-7 | 8-15 ...), and a round
    // samples what the guide learned up to two rounds before (GuideRounds::kDoublingPasses): before
    // round r begins, round r - 2 must have ended, and its Update is made, at the same point of
    // every render, so that what each pass samples does not depend on the waves, the memory
    // budget or the threads; round r - 1's last rays may still be in flight, and under a budget
    // they are traced beside round r's instead of draining to the last ray first. The processes
    // of a distributed render re-balance their bricks at the same points
    // (StreamScheduler::Rebalance), after a complete drain.
    const bool learns = owned_guide_ || scheduler_.ranks() != nullptr;
    const uint32_t round = RoundOfPass(uint32_t(s));
    if (learns) s_end = std::min(s_end, int(FirstPassOfRound(round + 1)));
    if (learns && uint32_t(s) == FirstPassOfRound(round) && round >= 2) {
        NAVE_RETURN_IF_ERROR(scheduler_.DrainRoundsBefore(*this, round - 1));
        if (scheduler_.ranks() != nullptr) {
            // Each process credited the paths it traced: all of them learn from all.
            NAVE_RETURN_IF_ERROR(ShareState(*scheduler_.ranks()));
            NAVE_RETURN_IF_ERROR(scheduler_.Rebalance());
        }
        if (owned_guide_) {
            NAVE_CHECK_EQ(owned_guide_->rounds_closed(), round - 2);
            owned_guide_->Update();
            log::Debug(
                "path guide after round {} (passes before {}): {} cells learning, {} guiding",
                round - 2, FirstPassOfRound(round - 1), owned_guide_->cells_used(),
                owned_guide_->cells_guiding());
        }
    }
    NAVE_RETURN_IF_ERROR(scheduler_.DrainInWaves(
        *this, pixels, wave, StreamScheduler::LastWave::kTailInFlight,
        [&](uint64_t first, uint64_t last) {
            for (int k = s; k < s_end; ++k)
                NAVE_RETURN_IF_ERROR(GenerateCameraRays(first, last, uint32_t(k)));
            return Status::Ok();
        }));
    // Processes that check a noise target or a time limit after the round agree on it with
    // collective sums, which no process may enter while rays are still on their way to it (its
    // senders would wait for it): the round ends with a complete drain there.
    const bool collective_check = checks && scheduler_.ranks() != nullptr;
    if (boundaries || collective_check) NAVE_RETURN_IF_ERROR(scheduler_.Drain(*this));
    // The last wave's tail may still be in flight: the noise estimate then misses a little of the
    // last pass, which the final estimate, after the last drain, does not.
    return s_end;
}

Status PathIntegrator::Finish(int passes, RenderStats* stats) {
    NAVE_RETURN_IF_ERROR(scheduler_.Drain(*this));  // the last wave's tail
    stats->samples_per_pixel = passes;
    stats->noise_relmse = NoiseEstimate(passes);
    if (owned_guide_) {
        stats->guide_cells = owned_guide_->cells_used();
        stats->guide_cells_guiding = owned_guide_->cells_guiding();
    }
    stats->camera_paths = uint64_t(film_->pixel_count()) * uint64_t(passes);
    film_->SetSamplesPerPixel(passes);
    return Status::Ok();
}

double PathIntegrator::NoiseEstimate(int passes) const {
    if (passes < 2) return std::nan("");
    return HalvesRelMse(film_->pixel_count(),
                        [&](size_t p) { return HalfLuminances(uint32_t(p), passes); });
}

std::array<double, 2> PathIntegrator::HalfLuminances(uint32_t pixel, int passes) const {
    return {film_->HalfLuminance(pixel, 0, passes), film_->HalfLuminance(pixel, 1, passes)};
}

bool PathIntegrator::ScatterAt(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                               const SurfaceHit& h, bool last, RayOutbox& out) {
    const Vec3f wo = -r.dir;
    Bsdf bsdf = BsdfAt(h, &r.lambda);
    const uint8_t flags = bsdf.Flags();
    if (flags == kBxdfUnset) return false;
    VertexRng rng(RayKey(scene_.settings.seed, r, iteration(), kStreamPath));
    // The side the path sees of the surface, which keeps the guide's histograms of a floor and
    // of the wall above it apart.
    const int side = PathGuide::SideSeenFrom(h.ns, wo);
    const GuidedBsdf continuation(bsdf, owned_guide_.get(), h.p, side, r.sample);
    if (flags & (kBxdfDiffuse | kBxdfGlossy)) {
        // What next-event estimation finds here, reflected once more, is light arriving at the
        // path's previous vertex from this one: its shadow rays credit the guide there.
        uint32_t credit = PathGuide::kNoCredit;
        float credit_scale = 0;
        const float beta = r.beta.Average();
        if (owned_guide_ && r.depth > 0 && !(r.flags & kSpecularBounce) && beta > 0 &&
            r.prev_pdf > 0 && r.guide_side != kMediumSide) {
            credit =
                owned_guide_->CreditKey(r.origin - r.dir * r.since_vertex, r.guide_side, r.dir);
            credit_scale = 1 / (beta * r.prev_pdf);
        }
        EstimateDirect(r, b, brick, h, bsdf, wo, rng, &continuation, scene_.sky != nullptr, credit,
                       credit_scale, out);
    }
    return Continue(r, h, continuation, rng, side, last);
}

}  // namespace nave::render
