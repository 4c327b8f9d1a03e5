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
namespace {

/// A rough power of a spectrum for choosing emitters: its mean over 400-700 nm.
float MeanVisible(const Spectrum& s) {
    double sum = 0;
    for (int l = 400; l <= 700; l += 10) sum += s.Evaluate(float(l));
    return float(sum / 31);
}

/// The rough power of an emissive material for choosing emitters: MeanVisible of its spectrum, or
/// for an emission texture the mean of its mean radiance over a few wavelength sets (any positive
/// weight keeps the estimate unbiased; a good one only lowers noise).
float EmissionPower(const SurfaceMaterial& m) {
    if (!(m.textures && m.textures->emission)) return MeanVisible(m.emission);
    double sum = 0;
    for (int i = 0; i < 8; ++i) {
        SampledWavelengths lambda = SampledWavelengths::SampleVisible((i + 0.5f) / 8);
        SampledSpectrum s = m.textures->MeanEmission(lambda);
        for (int k = 0; k < kNumWavelengths; ++k) sum += s[k];
    }
    // A black texture would give 0 and never be chosen; keep a floor so its triangles can still
    // emit.
    return std::max(float(sum / (8 * kNumWavelengths)), 1e-6f);
}

}  // namespace

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

    // One pass over the bricks that hold emissive or portal materials. A triangle stored in several
    // bricks (it crosses cells) is kept only in the brick whose cell holds its centroid.
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
            scene_, scheduler,
            [&](const SurfaceMaterial& sm) { return sm.emissive || (want_portals && sm.portal); },
            [&](const ResidentMesh& m, size_t t, uint32_t) {
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
                triangle_weights.push_back(power[m.material_ids[t]] * 2 * kPi * e.area);
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
            case Light::Kind::kSun:
                w *= l.SunSolidAngle() * target_area;
                break;
            case Light::Kind::kDirectional:
                w *= target_area;
                break;
            case Light::Kind::kPoint:
            case Light::Kind::kSpot:
                w *= 4 * kPi;
                break;
        }
        if (l.kind == Light::Kind::kSun || l.kind == Light::Kind::kDirectional) {
            e.guide = int(guides_.size());
            guides_.emplace_back(kGuideCells, scene_radius_);
        }
        emitters_.push_back(e);
        weights.push_back(w);
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
        e.kind = Emitter::Kind::kSky;
        emitters_.push_back(e);
        // Mean radiance over the sphere of directions (a fixed 256-direction Fibonacci set for a
        // sky model).
        double mean = 0;
        if (scene_.preetham) {
            const int n = 256;
            for (int i = 0; i < n; ++i) {
                float z = 1 - 2 * (float(i) + 0.5f) / float(n), phi = 2.39996323f * float(i);
                float rxy = std::sqrt(std::max(0.f, 1 - z * z));
                mean += MeanVisible(
                    scene_.SkySpectrum(Vec3f(rxy * std::cos(phi), rxy * std::sin(phi), z)));
            }
            mean = mean / n;  // with the ground below the horizon
        } else {
            mean = MeanVisible(scene_.sky_radiance);
        }
        // Through portals: lines cross them with measure 2 pi A_portals (both sides), through the
        // bounds 4 pi A_disc.
        weights.push_back(mean *
                          (sky_portals_ ? 2 * kPi * sky_portals_->area() : 4 * kPi * disk_area));
    }
    emitters_.insert(emitters_.end(), triangles.begin(), triangles.end());
    weights.insert(weights.end(), triangle_weights.begin(), triangle_weights.end());
    double total = 0;
    for (double w : weights) total += w;
    if (emitters_.empty() || !(total > 0)) {
        return InvalidArgumentError(
            "photon mode needs a light: the scene has no sun, light, sky or emissive "
            "material with power");
    }
    emitter_cdf_.assign(1, 0.0);
    for (double w : weights) emitter_cdf_.push_back(emitter_cdf_.back() + w / total);
    emitter_cdf_.back() = 1.0;
    return Status::Ok();
}

float PhotonEmitters::StartDistantPhoton(const Emitter& e, const Vec3f& to, const VertexRng& rng,
                                         RayRecord* r) {
    const Light& l = *e.light;
    const Frame frame = Frame::FromZ(l.to_light);
    const Vec3f plane_centre = scene_center_ + l.to_light * (2 * scene_radius_);
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
    const float t = Dot(plane_centre - on_line, l.to_light) / Dot(to, l.to_light);
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

void PhotonEmitters::Learn(std::span<const float> deposited) {
    const size_t n = std::min(deposited.size(), photon_cells_.size());
    for (size_t k = 0; k < n; ++k) {
        const uint32_t c = photon_cells_[k];
        if (c != kNoGuideCell) guides_[c >> 16].Add(uint16_t(c & 0xffff), deposited[k]);
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

void PhotonEmitters::EmitPhotons(uint64_t first, uint64_t last, uint32_t iteration,
                                 StreamScheduler& scheduler) {
    const float disk_area = kPi * scene_radius_ * scene_radius_;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, last, 1024), [&](const auto& range) {
        RayOutbox out;
        for (uint64_t i = range.begin(); i != range.end(); ++i) {
            RayRecord r{};
            r.kind = kPhotonRay;
            r.pixel = uint32_t(i);
            r.t_max = kInfinity;
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
            if (e.kind == Emitter::Kind::kLight) {
                const Light& l = *e.light;
                switch (l.kind) {
                    case Light::Kind::kSun:
                    case Light::Kind::kDirectional: {
                        const bool sun = l.kind == Light::Kind::kSun;
                        Vec3f to = sun ? l.SampleSun(u2) : l.to_light;
                        const float area = StartDistantPhoton(e, to, rng, &r);
                        r.dir = -to;
                        // Sun: L cos / (p_area p_dir) with p_dir = 1/Omega; directional: E /
                        // p_area.
                        r.beta = sun ? l.spectrum.Sample(lambda) *
                                           (Dot(to, l.to_light) * area * float(l.SunSolidAngle()))
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
                            float x = std::clamp(
                                (cos_a - l.cos_cone) / std::max(1e-6f, l.cos_falloff - l.cos_cone),
                                0.f, 1.f);
                            falloff = x * x * (3 - 2 * x);
                        }
                        r.beta = l.spectrum.Sample(lambda) * (falloff * 4 * kPi);
                        break;
                    }
                }
            } else if (e.kind == Emitter::Kind::kSky) {
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
                    const Vec3f to = SampleUniformSphere(u2);
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
                r.beta = scene_.SkyRadiance(-d, lambda) / density;
                r.flags = kFromSky;
            } else {
                // Uniform point on the triangle (Turk 1990 square-root parameterisation),
                // cosine-weighted direction on a side chosen with probability 1/2.
                const std::array<float, 3> w = SampleUniformTriangle(u1);
                Vec3f p = e.v0 * w[0] + e.v1 * w[1] + e.v2 * w[2];
                Vec3f n = rng.Uniform(5) < 0.5f ? e.n : -e.n;
                r.dir = Frame::FromZ(n).FromLocal(SampleCosineHemisphere(u2));
                r.origin = OffsetOrigin(p, n, r.dir);
                // L cos / (1/A * cos/pi * 1/2).
                std::array<float, 2> uv;
                for (int k = 0; k < 2; ++k)
                    uv[k] = e.uv[0][k] * w[0] + e.uv[1][k] * w[1] + e.uv[2][k] * w[2];
                r.beta = e.material->Emitted(e.has_uv ? &uv : nullptr, lambda) * (2 * kPi * e.area);
                r.flags = kFromAreaLight;
            }
            r.beta /= p_choice;
            if (r.beta.IsZero()) continue;

            // Queued at the first brick along it; a photon that misses the model carries nothing.
            ++out.counts.rays;
            const uint32_t next = scheduler.Route(r, 0, store::kNoBrick);
            if (next != store::kNoBrick) out.Send(next, store::kNoBrick, r);
        }
        scheduler.Flush(out);
    });
}

}  // namespace nave::render
