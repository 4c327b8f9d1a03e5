#include "src/render/integrators/visible_point_pass.h"

#include "src/render/transport/transport_common.h"

namespace nave::render {

VisiblePointPass::VisiblePointPass(const RenderScene& scene, Film* film, StreamScheduler& scheduler,
                                   const LightSampler& lights, VisiblePoints* visible_points,
                                   const PathGuide* gather_guide)
    : CameraPaths(scene, film, scheduler, lights, nullptr),
      visible_points_(visible_points),
      sky_from_photons_(scene.settings.sky_direct == RenderSettings::SkyDirect::kPhotons),
      final_gather_(scene.settings.final_gather),
      gather_guide_(gather_guide) {}

bool VisiblePointPass::ScatterAt(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                                 const SurfaceHit& h, bool last, RayOutbox& out) {
    const SurfaceMaterial& mat = *h.material;
    const Vec3f wo = -r.dir;
    if (mat.dispersive() && !r.lambda.SecondaryTerminated() &&
        r.beta.MaxValue() == r.beta.MinValue()) {
        // The path is about to keep one wavelength. Nothing it did so far depended on its own (the
        // throughput is the same at all four), so it may take its iteration's shared wavelengths
        // instead, which some photons carry too (visible_points.h).
        r.lambda = IterationWavelengths(uint64_t(scene_.settings.seed), iteration(),
                                        VisiblePoints::PixelChannel(r.pixel));
    }
    Bsdf bsdf = BsdfAt(h, &r.lambda);
    const uint8_t flags = bsdf.Flags();
    if (flags == kBxdfUnset) return false;
    VertexRng rng(RayKey(scene_.settings.seed, r, iteration(), kStreamPath));
    const int side = PathGuide::SideSeenFrom(h.ns, wo);
    if ((flags & kBxdfDiffuse) && final_gather_ && !(r.flags & kGathering)) {
        // Final gathering (Jensen 1996, "Global illumination using photon maps", 3.3): direct
        // light at the first diffuse vertex from next-event estimation weighed against the bounce
        // (power heuristic, as in path mode), which goes on to the vertex whose photons it reads.
        // A photon's power then reaches pixels scattered across the image instead of a disc of
        // the gather radius around it.
        const GuidedBsdf gather(bsdf, gather_guide_, h.p, side, r.sample);
        EstimateDirect(r, b, brick, h, bsdf, wo, rng, &gather, scene_.sky != nullptr,
                       PathGuide::kNoCredit, 0, out);
        // Caustics here come from the caustic photons (visible_points.h): the gather finds them
        // only by chance.
        if (visible_points_->caustic_points()) {
            visible_points_->AddCaustic(r.pixel, h.p, h.ns, wo, mat, h.has_uv ? &h.uv : nullptr,
                                        h.footprint, r.beta, r.lambda);
        }
        const bool goes_on = Continue(r, h, gather, rng, side, last);
        r.flags |= kGathering;  // after the gather bounce, which is no link of a specular chain
        return goes_on;
    }
    if (flags & kBxdfDiffuse) {
        // Where a gather bounce landed, every photon arriving is light leaving toward the first
        // diffuse vertex, its direct light included: no next-event estimation. Otherwise direct
        // light here is estimated, the sky's only if its photons do not bring it
        // (render.sky_direct = "photons").
        if (!(r.flags & kGathering)) {
            EstimateDirect(r, b, brick, h, bsdf, wo, rng, nullptr, scene_.sky && !sky_from_photons_,
                           PathGuide::kNoCredit, 0, out);
        }
        // SPPM: indirect light at the visible point comes from photons.
        visible_points_->Add(r.pixel, h.p, h.ns, wo, mat, h.has_uv ? &h.uv : nullptr, h.footprint,
                             r.beta, r.lambda);
        return false;
    }
    const GuidedBsdf continuation(bsdf, nullptr, h.p, side, r.sample);
    if (flags & kBxdfGlossy) {
        EstimateDirect(r, b, brick, h, bsdf, wo, rng, &continuation, scene_.sky != nullptr,
                       PathGuide::kNoCredit, 0, out);
    }
    return Continue(r, h, continuation, rng, side, last);
}

}  // namespace nave::render
