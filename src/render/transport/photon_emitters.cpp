#include "src/render/transport/photon_emitters.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "src/core/byte_stream.h"
#include "src/core/sampling.h"
#include "src/render/scene/materials/frame.h"
#include "src/render/stream/stream_scheduler.h"
#include "src/render/transport/transport_common.h"
#include "src/render/transport/visible_points.h"

namespace nave::render {

StatusOr<std::unique_ptr<PhotonEmitters>> PhotonEmitters::Build(const RenderScene& scene,
                                                                StreamScheduler& scheduler) {
    std::unique_ptr<PhotonEmitters> emitters(new PhotonEmitters(scene));
    NAVE_RETURN_IF_ERROR(emitters->Gather(scheduler));
    return emitters;
}

Status PhotonEmitters::Gather(StreamScheduler& scheduler) {
    const Bounds3f& bounds = scene_.source->bounds();
    scene_center_ = bounds.Center();
    scene_radius_ = std::max(1e-3f, 0.5f * Length(bounds.Diagonal()));
    const float disk_area = kPi * scene_radius_ * scene_radius_;

    // Passes over the bricks for the emissive and portal materials' triangles. A triangle stored
    // in several bricks (it crosses cells) is kept only in the brick whose cell holds its centroid.
    const bool want_portals =
        scene_.settings.photon_target == RenderSettings::PhotonTarget::kPortals;
    bool any_emissive = false, any_portal = false;
    for (const SurfaceMaterial& m : scene_.materials) {
        any_emissive |= m.emissive;
        any_portal |= m.portal;
    }
    if (want_portals && !any_portal) {
        return InvalidArgumentError(
            "render.photon_target = \"portals\" but no material has portal = true");
    }
    std::vector<double> weights;
    std::vector<TriangleLight> triangles;
    std::vector<double> triangle_weights;
    std::vector<std::array<Vec3f, 3>> portal_triangles;
    if (any_emissive || (want_portals && any_portal)) {
        // Per material, not per triangle: an emission texture's mean takes texture lookups.
        std::vector<float> power(scene_.materials.size(), 0.f);
        for (size_t i = 0; i < power.size(); ++i) {
            if (scene_.materials[i].emissive)
                power[i] = TriangleLight::MaterialPower(scene_.materials[i]);
        }
        // The portals only aim photons (their density mixes them with the whole disc and counts
        // the same triangles), so the coarsest levels serve; light sources are read at full
        // detail, in a second pass only when the model has any.
        // In a distributed render each process reads its own bricks, and all gather what all
        // found in the order one process finds it.
        RankGroup* ranks = scheduler.ranks();
        if (want_portals) {
            std::vector<uint32_t> bricks;  // of each triangle
            NAVE_RETURN_IF_ERROR(ForEachOwnedTriangle(
                scene_, scheduler, ScanDetail::kCoarsest,
                [](const SurfaceMaterial& sm) { return sm.portal; },
                [&](const ResidentMesh& m, size_t t, uint32_t b) {
                    portal_triangles.push_back(m.TrianglePositions(t));
                    bricks.push_back(b);
                }));
            if (ranks != nullptr) {
                NAVE_ASSIGN_OR_RETURN(portal_triangles, LightSampler::GatherPortals(
                                                            *ranks, portal_triangles, bricks));
            }
        }
        if (any_emissive) {
            struct Found {
                uint32_t brick, material, has_uv;
                std::array<Vec3f, 3> p;
                std::array<std::array<float, 2>, 3> uv;
            };
            std::vector<Found> found;
            NAVE_RETURN_IF_ERROR(ForEachOwnedTriangle(
                scene_, scheduler, ScanDetail::kFull,
                [](const SurfaceMaterial& sm) { return sm.emissive; },
                [&](const ResidentMesh& m, size_t t, uint32_t b) {
                    Found f{b, m.material_ids[t], m.HasUvs() ? 1u : 0u, m.TrianglePositions(t), {}};
                    if (m.HasUvs()) {
                        for (int k = 0; k < 3; ++k) f.uv[size_t(k)] = m.uvs[m.indices[3 * t + k]];
                    }
                    found.push_back(f);
                }));
            if (ranks != nullptr) {
                NAVE_ASSIGN_OR_RETURN(found,
                                      GatherInBrickOrder(*ranks, std::span<const Found>(found)));
            }
            for (const Found& f : found) {
                if (f.material >= scene_.materials.size()) {
                    return InternalError("an emissive triangle of material {} of {}", f.material,
                                         scene_.materials.size());
                }
                std::optional<TriangleLight> light =
                    TriangleLight::Make(f.p, scene_.materials[f.material],
                                        f.has_uv ? &f.uv : nullptr, power[f.material]);
                if (!light) continue;
                triangles.push_back(std::move(*light));
                triangle_weights.push_back(triangles.back().Power(PhotonTarget()));
            }
        }
    }
    for (const std::unique_ptr<Light>& l : scene_.lights) {
        Emitter e;
        e.light = l.get();
        e.distant = l->distant();
        float target_area = disk_area;
        if (want_portals && e.distant != nullptr) {
            PortalProjection projection(portal_triangles, e.distant->to_light());
            if (!projection.empty()) {
                e.portal = int(portals_.size());
                target_area = float(projection.total_area());
                portals_.push_back(std::move(projection));
            }
        }
        if (e.distant != nullptr) {
            e.guide = int(guides_.size());
            guides_.emplace_back(kGuideCells, scene_radius_);
        }
        emitters_.push_back(e);
        PhotonTarget target;
        target.area = target_area;
        weights.push_back(l->Power(target));
    }
    if (!guides_.empty()) {
        photon_cells_.assign(
            std::min<uint64_t>(scene_.settings.photons_per_iteration, kMaxLearnedPhotons),
            kNoGuideCell);
    }
    if (want_portals && !portal_triangles.empty()) {
        NAVE_ASSIGN_OR_RETURN(sky_portals_, SkyPortals::Build(*scene_.source, portal_triangles));
    }
    if (scene_.sky) {
        Emitter e;
        e.light = scene_.sky.get();
        e.flags = kFromSky;
        emitters_.push_back(e);
        // Through portals: lines cross them with measure 2 pi A_portals (both sides), through the
        // bounds 4 pi A_disc.
        PhotonTarget target;
        target.line_measure = sky_portals_ ? 2 * kPi * sky_portals_->area() : 4 * kPi * disk_area;
        weights.push_back(scene_.sky->Power(target));
    }
    triangle_lights_ = std::move(triangles);
    for (const TriangleLight& t : triangle_lights_) {
        Emitter e;
        e.light = &t;
        e.flags = kFromAreaLight;
        emitters_.push_back(e);
    }
    weights.insert(weights.end(), triangle_weights.begin(), triangle_weights.end());
    double total = 0;
    for (double w : weights) total += w;
    if (emitters_.empty() || !(total > 0)) {
        return InvalidArgumentError(
            "photon mode needs a light: the scene has no sun, light, sky or emissive "
            "material with power");
    }
    total_power_ = total;
    emitter_cdf_.assign(1, 0.0);
    for (double w : weights) emitter_cdf_.push_back(emitter_cdf_.back() + w / total);
    emitter_cdf_.back() = 1.0;
    return Status::Ok();
}

float PhotonEmitters::StartDistantPhoton(const Emitter& e, const Vec3f& to, const VertexRng& rng,
                                         RayRecord* r) {
    const Vec3f& to_light = e.distant->to_light();
    const Frame frame = Frame::FromZ(to_light);
    const Vec3f plane_centre = scene_center_ + to_light * (2 * scene_radius_);
    const float disk_area = kPi * scene_radius_ * scene_radius_;
    const PortalProjection* portals = e.portal >= 0 ? &portals_[size_t(e.portal)] : nullptr;
    PhotonGuide& guide = guides_[size_t(e.guide)];
    // The strategies' shares: portals and guide when they exist, the disc for the rest.
    float guide_share = guide.trained() ? kGuidePhotonShare : 0.f;
    float portal_share = portals != nullptr ? kPortalPhotonShare * (1 - guide_share) : 0.f;
    const float disc_share = 1 - guide_share - portal_share;
    const float u = rng.Uniform(8);
    Vec3f on_line;
    if (u < portal_share) {
        on_line = portals->Sample(rng.Uniform(6), rng.Uniform(1), rng.Uniform(2));
    } else if (u < portal_share + guide_share) {
        const Point2f q = guide.Sample(rng.Uniform(6), Point2f(rng.Uniform(1), rng.Uniform(2)));
        on_line = plane_centre + frame.x * q.x + frame.y * q.y;
    } else {
        const Point2f d = SampleUniformDiskConcentric(Point2f(rng.Uniform(1), rng.Uniform(2)));
        on_line = plane_centre + frame.x * (d.x * scene_radius_) + frame.y * (d.y * scene_radius_);
    }
    // Where the photon's line (through on_line along -to) crosses the plane facing the light: the
    // coordinates every strategy's density is measured in.
    const float t = Dot(plane_centre - on_line, to_light) / Dot(to, to_light);
    r->origin = on_line + to * t;
    const float x = Dot(r->origin - scene_center_, frame.x),
                y = Dot(r->origin - scene_center_, frame.y);
    float density = 0;
    if (x * x + y * y <= scene_radius_ * scene_radius_) density += disc_share / disk_area;
    if (guide_share > 0) density += guide_share * guide.Pdf(x, y);
    if (portals != nullptr) {
        const int count = sky_portals_->ForEachCrossing(r->origin, -to, 4 * scene_radius_,
                                                        [](const BrickHit&) {});
        density += portal_share * float(count) / float(portals->total_area());
    }
    if (r->pixel < photon_cells_.size()) {
        const uint16_t cell = guide.Cell(x, y);
        photon_cells_[r->pixel] =
            cell == PhotonGuide::kNoCell ? kNoGuideCell : (uint32_t(e.guide) << 16) | cell;
    }
    return density > 0 ? 1 / density : 0.f;
}

void PhotonEmitters::Learn(std::span<const uint64_t> deposited, double fixed_per_luminance) {
    const size_t n = std::min(deposited.size(), photon_cells_.size());
    for (size_t k = 0; k < n; ++k) {
        const uint32_t c = photon_cells_[k];
        if (c != kNoGuideCell) {
            guides_[c >> 16].Add(uint16_t(c & 0xffff),
                                 float(double(deposited[k]) / fixed_per_luminance));
        }
    }
    for (PhotonGuide& guide : guides_) guide.Update();
    std::fill(photon_cells_.begin(), photon_cells_.end(), kNoGuideCell);
}

void PhotonEmitters::SaveState(ByteWriter* out) const {
    out->Put(uint32_t(guides_.size()));
    for (const PhotonGuide& guide : guides_)
        out->PutArray(guide.learned().data(), guide.learned().size());
}

Status PhotonEmitters::LoadState(ByteReader* in) {
    uint32_t guides = 0;
    NAVE_RETURN_IF_ERROR(in->Get(&guides, "photon guide count"));
    if (guides != guides_.size()) {
        return DataLossError("{}: {} photon guides, this scene has {}", in->what(), guides,
                             guides_.size());
    }
    for (PhotonGuide& guide : guides_) {
        std::vector<double> learned(guide.learned().size());
        NAVE_RETURN_IF_ERROR(in->GetArray(learned.data(), learned.size(), "photon guide cells"));
        NAVE_CHECK(guide.SetLearned(std::move(learned)));
    }
    return in->ExpectEnd();
}

void PhotonEmitters::EmitPhotons(
    uint64_t first, uint64_t last, uint32_t iteration, float footprint, StreamScheduler& scheduler,
    const std::function<void(RayRecord&, RayOutbox&)>& meets_no_brick) {
    const float disk_area = kPi * scene_radius_ * scene_radius_;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, last, 1024), [&](const auto& range) {
        RayOutbox out;
        for (uint64_t i = range.begin(); i != range.end(); ++i) {
            RayRecord r{};
            r.kind = kPhotonRay;
            r.pixel = uint32_t(i);
            r.t_max = kInfinity;
            r.cone_width = footprint;
            VertexRng rng(RayKey(scene_.settings.seed, r, iteration, kStreamEmit));
            // Each photon its own wavelengths, but one in kSharedWavelengthEvery the iteration's
            // (visible_points.h).
            const int channel =
                VisiblePoints::PhotonChannel(i, uint64_t(scene_.settings.photons_per_iteration));
            const SampledWavelengths lambda =
                channel != VisiblePoints::kOwnWavelengths
                    ? IterationWavelengths(uint64_t(scene_.settings.seed), iteration, channel)
                    : SampledWavelengths::SampleVisible(rng.Uniform(7));
            r.lambda = lambda;
            float u = rng.Uniform(0);
            size_t k =
                size_t(std::upper_bound(emitter_cdf_.begin() + 1, emitter_cdf_.end(), double(u)) -
                       (emitter_cdf_.begin() + 1));
            k = std::min(k, emitters_.size() - 1);
            const float p_choice = float(emitter_cdf_[k + 1] - emitter_cdf_[k]);
            if (p_choice <= 0) continue;
            const Emitter& e = emitters_[k];
            Point2f u1(rng.Uniform(1), rng.Uniform(2)), u2(rng.Uniform(3), rng.Uniform(4));
            // Photons from distant sources (sun, directional, sky) start on a disc facing the
            // source that covers the model's bounding sphere: every photon that can reach the model
            // does (the model's bounds projected onto the light's direction; windows are reached
            // through them).
            auto disc_origin = [&](const Vec3f& toward) {
                Frame f = Frame::FromZ(toward);
                Point2f d = SampleUniformDiskConcentric(u1);
                return scene_center_ + toward * (2 * scene_radius_) + f.x * (d.x * scene_radius_) +
                       f.y * (d.y * scene_radius_);
            };
            if (e.distant != nullptr) {
                const Vec3f to = e.distant->SamplePhotonDirection(u2);
                const float area = StartDistantPhoton(e, to, rng, &r);
                r.dir = -to;
                r.beta = e.distant->PhotonPower(to, area, lambda);
            } else if (e.light == scene_.sky.get()) {
                Vec3f d;
                if (sky_portals_ && rng.Uniform(8) < kSkyPortalPhotonShare) {
                    // A point uniform on the portals' area, a cosine-weighted direction on a random
                    // side.
                    size_t i = 0;
                    const Vec3f p = sky_portals_->SamplePoint(rng.Uniform(6), u1, &i);
                    const auto& t = sky_portals_->triangle(i);
                    Vec3f n = Normalize(Cross(t[1] - t[0], t[2] - t[0]));
                    if (rng.Uniform(5) < 0.5f) n = -n;
                    d = Frame::FromZ(n).FromLocal(SampleCosineHemisphere(u2));
                    r.origin = p - d * (2 * scene_radius_);
                } else {
                    // A uniform direction, a point uniform on the disc facing it.
                    const Vec3f to = SkyLight::SampleUniform(u2);
                    r.origin = disc_origin(to);
                    d = -to;
                }
                r.dir = d;
                // The line's density in the measure dA_perp dw: 1 / (4 pi A_disc) through the
                // bounds; through the portals count / (2 pi A_portals), count = portals the line
                // crosses (Veach's balance heuristic over the portals); aimed at windows, the
                // mixture of the two.
                float density = 1 / (4 * kPi * disk_area);
                if (sky_portals_) {
                    const int count = sky_portals_->ForEachCrossing(r.origin, d, 4 * scene_radius_,
                                                                    [](const BrickHit&) {});
                    density = kSkyPortalPhotonShare * float(count) /
                                  float(2 * kPi * sky_portals_->area()) +
                              (1 - kSkyPortalPhotonShare) * density;
                }
                r.beta = scene_.sky->Radiance(-d, lambda) / density;
            } else {
                // A photon of a light at a place: point, spot, emissive triangle.
                const PhotonSample s = e.light->SamplePhoton({u1, u2, rng.Uniform(5)}, lambda);
                r.origin = s.origin;
                r.dir = s.dir;
                r.beta = s.power;
            }
            r.flags = e.flags;
            // Through a medium from where it starts (the first brick it enters flies it there).
            if (scene_.medium) r.flags |= kFlightFromOrigin;
            r.beta /= p_choice;
            if (r.beta.IsZero()) continue;

            // In a distributed render the process owning the photon's first brick traces it.
            if (!scheduler.MakesHere(r, i)) continue;
            // Queued at the first brick along it.
            ++out.counts.rays;
            const uint32_t next = scheduler.Route(r, 0, store::kNoBrick);
            if (next != store::kNoBrick) {
                out.Send(next, store::kNoBrick, r);
            } else if (meets_no_brick) {
                meets_no_brick(r, out);
            }
        }
        scheduler.Flush(out);
    });
}

}  // namespace nave::render
