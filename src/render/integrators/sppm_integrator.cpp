#include "src/render/integrators/sppm_integrator.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "src/core/byte_stream.h"
#include "src/core/image_error.h"
#include "src/core/log.h"
#include "src/core/progress.h"
#include "src/render/scene/surface_hit.h"
#include "src/render/transport/medium_flight.h"
#include "src/render/transport/rng.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {

StatusOr<std::unique_ptr<SppmIntegrator>> SppmIntegrator::Create(const RenderScene& scene,
                                                                 Film* film,
                                                                 StreamScheduler& scheduler) {
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<PhotonEmitters> emitters,
                          PhotonEmitters::Build(scene, scheduler));
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<LightSampler> lights,
                          LightSampler::Create(scene, scheduler, emitters->sky_portals(),
                                               emitters->typical_photon_power()));
    std::unique_ptr<PathGuide> gather_guide;
    if (scene.settings.final_gather && !scene.source->bounds().Empty()) {
        // Credited with photon powers, not radiances: its fixed point is scaled to a photon's.
        gather_guide =
            std::make_unique<PathGuide>(scene.source->bounds(), kGuideCoarseCellsLongAxis,
                                        kGatherGuideMaxCells, emitters->typical_photon_power());
    }
    return std::unique_ptr<SppmIntegrator>(new SppmIntegrator(
        scene, film, scheduler, std::move(emitters), std::move(lights), std::move(gather_guide)));
}

namespace {

/// r_1: render.initial_radius_m, or 1 % of the model's diameter.
float InitialRadius(const RenderScene& scene, const PhotonEmitters& emitters) {
    return scene.settings.initial_radius_m > 0 ? scene.settings.initial_radius_m
                                               : 0.01f * 2 * emitters.scene_radius();
}

}  // namespace

SppmIntegrator::SppmIntegrator(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                               std::unique_ptr<PhotonEmitters> emitters,
                               std::unique_ptr<LightSampler> lights,
                               std::unique_ptr<PathGuide> gather_guide)
    : scene_(scene),
      film_(film),
      scheduler_(scheduler),
      emitters_(std::move(emitters)),
      lights_(std::move(lights)),
      visible_(std::make_unique<VisiblePoints>(
          film->pixel_count(), scene.source->brick_count(), InitialRadius(scene, *emitters_),
          scene.settings.alpha, UsesCausticPoints(scene.settings, scene.materials))),
      gather_guide_(std::move(gather_guide)),
      camera_pass_(scene, film, scheduler, *lights_, visible_.get(), gather_guide_.get()),
      deposit_to_fixed_(4294967296.0 / std::max(1e-30, emitters_->typical_photon_power())),
      sky_direct_photons_(scene.settings.sky_direct == RenderSettings::SkyDirect::kPhotons),
      final_gather_(scene.settings.final_gather) {}

Status SppmIntegrator::Restore(const RenderSession& session) {
    NAVE_ASSIGN_OR_RETURN(std::string_view points, session.Section("visible_points"));
    ByteReader points_in(points, session.resume_name() + " section visible_points");
    NAVE_RETURN_IF_ERROR(visible_->LoadState(&points_in));
    // The checkpoint's density sums are every process's: one process holds them, as its film.
    if (scheduler_.ranks() != nullptr && scheduler_.ranks()->rank() != 0) visible_->ClearSums();
    NAVE_ASSIGN_OR_RETURN(std::string_view learned, session.Section("photon_emitters"));
    ByteReader learned_in(learned, session.resume_name() + " section photon_emitters");
    NAVE_RETURN_IF_ERROR(emitters_->LoadState(&learned_in));
    if (gather_guide_) {
        NAVE_ASSIGN_OR_RETURN(std::string_view guide, session.Section("gather_guide"));
        ByteReader guide_in(guide, session.resume_name() + " section gather_guide");
        NAVE_RETURN_IF_ERROR(gather_guide_->LoadState(&guide_in));
    }
    if (SkyWindows* windows = lights_->sky_windows()) {
        NAVE_ASSIGN_OR_RETURN(std::string_view sums, session.Section("sky_windows"));
        ByteReader sums_in(sums, session.resume_name() + " section sky_windows");
        NAVE_RETURN_IF_ERROR(windows->LoadState(&sums_in));
        return sums_in.ExpectEnd();
    }
    return Status::Ok();
}

void SppmIntegrator::Save(Checkpoint* checkpoint) const {
    ByteWriter points, learned;
    visible_->SaveState(&points);
    emitters_->SaveState(&learned);
    checkpoint->sections["visible_points"] = points.Take();
    checkpoint->sections["photon_emitters"] = learned.Take();
    if (gather_guide_) {
        ByteWriter guide;
        gather_guide_->SaveState(&guide);
        checkpoint->sections["gather_guide"] = guide.Take();
    }
    if (const SkyWindows* windows = lights_->sky_windows()) {
        ByteWriter sums;
        windows->SaveState(&sums);
        checkpoint->sections["sky_windows"] = sums.Take();
    }
}

StatusOr<int> SppmIntegrator::RenderRounds(int done, bool) {
    // Every iteration ends with its photons drained: a checkpoint needs no extra drain.
    const uint64_t pixels = film_->pixel_count();
    const uint64_t photons = scene_.settings.photons_per_iteration;
    const uint64_t wave = scene_.settings.wave_paths;
    iteration_ = uint32_t(done);
    camera_pass_.set_iteration(iteration_);
    visible_->BeginIteration(uint64_t(scene_.settings.seed), iteration_, photons);
    // Visible points must all be in place before photons arrive: waves overlap within each pass
    // only. So the queues hold camera paths and their shadow rays, then photons, never both,
    // and each pass is drained by its own processor. The camera pass's rays may meet coarse
    // levels in whichever process they are; a photon deposits at the visible points of the
    // brick it meets, which only the brick's owner holds.
    NAVE_RETURN_IF_ERROR(scheduler_.TraceCoarseLevelsHere(true));
    NAVE_RETURN_IF_ERROR(
        scheduler_.DrainInWaves(camera_pass_, pixels, wave, StreamScheduler::LastWave::kDrained,
                                [&](uint64_t first, uint64_t last) {
                                    return camera_pass_.GenerateCameraRays(first, last, 0);
                                }));
    NAVE_RETURN_IF_ERROR(scheduler_.TraceCoarseLevelsHere(false));
    RankGroup* ranks = scheduler_.ranks();
    if (ranks != nullptr) {
        // Photons traced here reach the points in this process's bricks, wherever they were made.
        const RayExchange& exchange = scheduler_.exchange();
        NAVE_RETURN_IF_ERROR(visible_->ShareWithOwners(
            *ranks, scheduler_.tree(), [&](uint32_t brick) { return exchange.Owner(brick); },
            scene_.materials));
        visible_->BuildBrickGrids(scheduler_.tree(),
                                  [&](uint32_t brick) { return exchange.Owns(brick); });
    } else {
        visible_->BuildBrickGrids(scheduler_.tree());
    }
    deposited_.assign(emitters_->learned_photons(), 0);
    NAVE_RETURN_IF_ERROR(scheduler_.DrainInWaves(
        *this, photons, wave, StreamScheduler::LastWave::kDrained,
        [&](uint64_t first, uint64_t last) {
            emitters_->EmitPhotons(first, last, iteration_, visible_->radius(), scheduler_,
                                   [&](RayRecord& r, RayOutbox& out) {
                                       // Through empty cells only: a medium there may still
                                       // scatter it toward a brick.
                                       r.flags &= uint8_t(~kFlightFromOrigin);
                                       FlyPhoton(r, 0, r.t_max, store::kNoBrick, nullptr, out);
                                   });
            return Status::Ok();
        }));
    if (ranks != nullptr) NAVE_RETURN_IF_ERROR(ShareLearning(*ranks));
    emitters_->Learn(deposited_, deposit_to_fixed_);
    if (SkyWindows* windows = lights_->sky_windows()) windows->Update();
    if (gather_guide_) {
        gather_guide_->Update();
        log::Debug("gather guide after {} iterations: {} cells learning, {} guiding",
                   iteration_ + 1, gather_guide_->cells_used(), gather_guide_->cells_guiding());
    }
    visible_->EndIteration(Film::SampleHalf(iteration_));
    // An iteration is the whole job's: in a distributed render the first process counts it.
    if (progress_ != nullptr && (ranks == nullptr || ranks->rank() == 0)) progress_->Add(1);
    return done + 1;
}

Status SppmIntegrator::Finish(int done, RenderStats* stats) {
    const uint64_t pixels = film_->pixel_count();
    const uint64_t photons = scene_.settings.photons_per_iteration;
    // Direct light and specular chains were summed by the film over `done` iterations; the photon
    // estimate is added as `done` times the per-iteration mean so the film's division by its sample
    // count holds.
    film_->SetSamplesPerPixel(done);
    const double emitted = double(photons) * done;
    RankGroup* ranks = scheduler_.ranks();
    if (ranks != nullptr) {
        // Every process's deposits in every process, for the noise estimate once the films are
        // summed (RenderStreams); the first process alone adds them to its film, so that the
        // films' sum counts them once.
        NAVE_RETURN_IF_ERROR(
            visible_->CombineSums([&](std::span<double> v) { return ranks->SumEverywhere(v); }));
    }
    if (ranks == nullptr || ranks->rank() == 0) {
        for (uint64_t p = 0; p < pixels; ++p) {
            film_->AddXYZ(uint32_t(p), visible_->IndirectXYZ(uint32_t(p), emitted) * double(done),
                          Film::kNoHalf);
        }
    }
    stats->noise_relmse = NoiseEstimate(done);
    stats->iterations = done;
    stats->samples_per_pixel = done;
    stats->camera_paths = pixels * uint64_t(done);
    stats->photons = emitted;
    if (const SkyWindows* windows = lights_->sky_windows())
        stats->sky_window_regions = windows->regions();
    return Status::Ok();
}

Status SppmIntegrator::ShareLearning(RankGroup& ranks) {
    // What each process learned from the photons it traced, summed in integers: every process
    // then learns the same as one process would.
    NAVE_RETURN_IF_ERROR(ranks.SumEverywhere(std::span<uint64_t>(deposited_)));
    if (SkyWindows* windows = lights_->sky_windows()) {
        NAVE_RETURN_IF_ERROR(windows->ShareRecords(
            [&](std::span<const std::byte> mine) { return ranks.GatherEverywhere(mine); }));
    }
    if (gather_guide_) {
        NAVE_RETURN_IF_ERROR(gather_guide_->ShareCredits(
            [&](std::span<uint64_t> values) { return ranks.SumEverywhere(values); }));
    }
    return Status::Ok();
}

Status SppmIntegrator::ShareState(RankGroup& ranks) {
    // Between iterations the guides and windows are every process's already (ShareLearning): the
    // density sums go to the first process, as the films do (RenderSession::AtBoundary).
    NAVE_RETURN_IF_ERROR(
        visible_->CombineSums([&](std::span<double> v) { return ranks.SumEverywhere(v); }));
    if (ranks.rank() != 0) visible_->ClearSums();
    return Status::Ok();
}

double SppmIntegrator::NoiseEstimate(int iterations) const {
    if (iterations < 2) return std::nan("");
    // Pixel by pixel: no image is held.
    return HalvesRelMse(film_->pixel_count(),
                        [&](size_t p) { return HalfLuminances(uint32_t(p), iterations); });
}

std::array<double, 2> SppmIntegrator::HalfLuminances(uint32_t pixel, int iterations) const {
    // Each half: the film's direct light and specular chains of its iterations (even or odd) plus
    // the photon estimate of the same iterations.
    const double photons = double(scene_.settings.photons_per_iteration);
    const int even = (iterations + 1) / 2,
              odd = iterations / 2;  // iterations 0, 2, 4... and 1, 3...
    const double emitted[2] = {photons * even, photons * odd};
    std::array<double, 2> half;
    for (int h = 0; h < 2; ++h) {
        half[h] = film_->HalfLuminance(pixel, h, iterations) +
                  visible_->IndirectHalfY(pixel, h, emitted[h]);
    }
    return half;
}

void SppmIntegrator::ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                                  std::span<const RayRecord> rays, RayOutbox& out) {
    for (RayRecord r : rays) {
        if (r.flags & kFlightFromOrigin) {
            // The stretch before the first brick lies in empty cells of the model or outside it,
            // where only a medium that holds everywhere has density (and, in photon mode, only
            // inside the model's box: MakeMedium).
            r.flags &= uint8_t(~kFlightFromOrigin);
            if (!FlyPhoton(r, 0, r.t_enter, brick, &resident, out)) continue;
        }
        TraceInBrick(
            r, brick, resident, scheduler_, out,
            [&](RayRecord& photon, float t0, float t1) {
                return FlyPhoton(photon, t0, t1, brick, &resident, out);
            },
            [&](RayRecord& photon, const BrickHit& hit) {
                EndFlightAtSurface(scene_.MediumOf(photon.medium), &photon);
                return ShadePhoton(photon, brick, resident, hit);
            },
            [](const RayRecord&) {});  // photons leaving the model carry nothing back
    }
}

bool SppmIntegrator::FlyPhoton(RayRecord& r, float t0, float t1, uint32_t b,
                               const ResidentBrick* brick, RayOutbox& out) {
    const Medium* in = scene_.MediumOf(r.medium);
    if (in == nullptr) return true;
    const Medium& medium = *in;
    const DensityField* field = medium.DensityIn(brick);
    if (field == nullptr || !(t1 > t0)) return true;
    // The photon stream's flight dimensions, which no surface vertex uses (as a path's).
    const VertexRng rng(RayKey(scene_.settings.seed, r, iteration_, kStreamPhoton));
    const float depth = FlightDepth(medium, r.lambda, rng.Uniform(kDimFlightChoice),
                                    rng.Uniform(kDimFlightDistance));
    const float t = Fly(field, depth, t0, t1, &r);
    if (!(t < kInfinity)) return true;
    // A scattering in the air: the photon's power takes the scattering's weight (absorption on
    // the way included), Russian roulette on its change as at surfaces, and the phase function
    // samples where it goes. Photons are stored on surfaces only: the light a camera path's
    // medium vertex scatters comes from next-event estimation there and from the photons at the
    // surface its continuation reaches (docs/render.md, "Participating media").
    if (uint32_t(r.depth) + 1 >= uint32_t(scene_.settings.max_depth)) return false;
    const SampledSpectrum w = ScatterWeight(medium, r.lambda, depth);
    const float q = std::max(0.f, 1 - w.Average());
    if (rng.Uniform(kDimRoulette) < q) return false;
    r.beta *= w / (1 - q);
    if (r.beta.IsZero()) return false;
    const PhaseSample ps =
        medium.phase().Sample(r.dir, Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)));
    r.flags = ExtendSpecularChain(r.flags, /*specular=*/false);
    LeaveMediumVertex(&r, t, ps.wi);
    ++out.counts.rays;
    const uint32_t next = scheduler_.Route(r, 0, store::kNoBrick);
    // The stretch from the vertex to the next brick is this brick's to fly (it may scatter again).
    if (!FlyPhoton(r, 0, next == store::kNoBrick ? r.t_max : r.t_enter, b, brick, out))
        return false;
    if (next != store::kNoBrick) out.Send(next, b, r);
    return false;
}

void SppmIntegrator::LearnWindow(const RayRecord& r, const SurfaceHit& h) {
    SkyWindows* windows = lights_->sky_windows();
    if (windows == nullptr) return;
    // The window the photon came in through: the first portal back along its path (panes let it
    // through without bending it).
    const Vec3f wo = -r.dir;
    const std::optional<BrickHit> window = emitters_->sky_portals()->FirstCrossing(h.p, wo);
    if (!window) return;  // outside, or in through an opening that is not a portal
    windows->Record(h.p, PathGuide::SideSeenFrom(h.ns, wo), window->triangle,
                    double(r.beta.Average()));
}

bool SppmIntegrator::ShadePhoton(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                                 const BrickHit& hit) {
    SurfaceHit h = MakeSurfaceHit(scene_, brick, hit, r.dir);
    const SurfaceMaterial& mat = *h.material;
    const Vec3f wo = -r.dir;
    AbsorbInsideGlass(mat, h, &r);
    Bsdf bsdf = BsdfAt(h, &r.lambda);
    const uint8_t flags = bsdf.Flags();
    if (flags == kBxdfUnset) return false;
    // Direct light from the sun and the other delta or disc lights is next-event estimated at the
    // visible points: deposit only photons that bounced, or that come from emitters no estimator
    // samples (emissive surfaces; the sky with render.sky_direct = "photons"). With final
    // gathering the visible points are one bounce past that estimate: every photon counts.
    if ((final_gather_ || r.depth > 0 || (r.flags & kFromAreaLight) ||
         ((r.flags & kFromSky) && sky_direct_photons_)) &&
        (flags & kBxdfDiffuse)) {
        const float added = visible_->Deposit(
            scheduler_.source().BrickOfSlot(b), h.p, h.ng, wo, r.beta, r.lambda,
            VisiblePoints::PhotonChannel(r.pixel, uint64_t(scene_.settings.photons_per_iteration)),
            (r.flags & kSpecularChain) != 0);
        // One writer per photon: a photon is traced by one thread at a time. In fixed point, so
        // that a photon's deposits in several processes add up to one process's sum exactly.
        if (r.pixel < deposited_.size())
            deposited_[r.pixel] +=
                uint64_t(std::llround(std::clamp(double(added) * deposit_to_fixed_, 0.0, 1e18)));
    }
    // One sky photon in kLearnWindowEvery teaches the windows: enough to learn them in an
    // iteration of the abbey, for a quarter of the cost (a ray through the portals' scene each).
    if ((r.flags & kFromSky) && r.depth == 0 && (flags & kBxdfDiffuse) &&
        r.pixel % kLearnWindowEvery == 0)
        LearnWindow(r, h);
    if (gather_guide_ && r.depth > 0 && (flags & kBxdfDiffuse)) {
        // Light that bounced before arriving here: what a gather from here should look for (its
        // direct light is next-event estimated). Jensen 1995, "Importance driven path tracing
        // using the photon map", guides the bounce by the photons around the vertex likewise.
        const int side = PathGuide::SideSeenFrom(h.ns, wo);
        // The gather guide closes a round at every Update (GuideRounds::kEveryUpdate): the
        // photon's iteration is the round, whatever pass is given.
        gather_guide_->Credit(gather_guide_->CreditKey(h.p, side, wo),
                              std::max(0.0, double(r.beta.Average())), iteration_);
    }
    // As for paths, a photon at its last bounce still passes through thin glass.
    const bool last = uint32_t(r.depth) + 1 >= uint32_t(scene_.settings.max_depth);
    if (last && mat.thin_glass() == nullptr) return false;
    VertexRng rng(RayKey(scene_.settings.seed, r, iteration_, kStreamPhoton));
    std::optional<BsdfSample> bs = bsdf.Sample(
        wo, rng.Uniform(kDimBsdfChoice), Point2f(rng.Uniform(kDimBsdf0), rng.Uniform(kDimBsdf1)),
        r.lambda, TransportMode::kImportance);
    if (!bs) return false;
    SampledSpectrum beta = r.beta * bs->f * (std::abs(Dot(bs->wi, h.ns)) / bs->pdf);
    r.vertex += 1;
    if (IsPassThrough(mat, *bs)) {
        // Through a window pane: not a bounce, so a photon that arrives next at a diffuse surface
        // is still direct sunlight, which next-event estimation through glass already counts.
        r.beta = beta;
        return PassThrough(r, h, bs->wi);
    }
    if (last) return false;
    // Russian roulette on the photon's change of power (pbrt-v4 SPPM photon pass).
    float q = std::max(0.f, 1 - beta.Average() / std::max(1e-20f, r.beta.Average()));
    if (rng.Uniform(kDimRoulette) < q) return false;
    r.beta = beta / (1 - q);
    r.flags = ExtendSpecularChain(r.flags, bs->IsSpecular() && mat.MakesCaustics());
    return Bounce(r, h, bs->wi, bs->IsSpecular());
}

}  // namespace nave::render
