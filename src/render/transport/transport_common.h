#pragma once
// What path tracing, photon tracing, light sampling and photon emission share: the layout of a
// vertex's random numbers, the MIS weight, one pass over the triangles of chosen materials, and the
// walk of a path or photon through a brick.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "src/core/byte_stream.h"
#include "src/core/status.h"
#include "src/render/bricks/brick_walk.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/surface_hit.h"
#include "src/render/stream/level_choice.h"
#include "src/render/stream/ray.h"
#include "src/render/stream/stream_scheduler.h"
#include "src/render/transport/rng.h"

namespace nave::render {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// Dimensions of a vertex's random numbers (VertexRng::Uniform).
enum RngDim : uint32_t {
    // The camera stream only: pixel position, lens, wavelengths.
    kDimPixelX = 0,
    kDimPixelY,
    kDimLens0,
    kDimLens1,
    kDimLambda,
    // The path stream, as a ray starts: where it scatters in a medium (FlightDepth).
    kDimFlightChoice = 5,
    kDimFlightDistance,
    // Where along its flight a path ray looks at what the medium emits (EmissionAlong).
    kDimEmissionPoint,
    // Every scattering vertex: BSDF lobe and direction, Russian roulette.
    kDimBsdfChoice = 8,
    kDimBsdf0,
    kDimBsdf1,
    kDimRoulette,
    // Path guiding: the guide or the BSDF, then the guide's bin and the direction in it.
    kDimGuideChoice,
    kDimGuideBin,
    kDimGuide0,
    kDimGuide1,
    kDimLight0 = 16,  // next-event estimation: two per light, then the sky's
};

/// The random streams of a ray (RngKey::stream).
enum RngStream : uint32_t {
    kStreamPath = 0,
    kStreamPhoton = 1,
    kStreamCamera = 2,
    kStreamEmit = 3,
    kStreamWavelengths = 4,  // photon mode: the iteration's shared wavelengths
};

/// The key of ray r's random numbers in `stream`: its path (or photon), its vertex and the SPPM
/// iteration (0 in path mode) under the render's `seed`.
inline RngKey RayKey(uint64_t seed, const RayRecord& r, uint32_t iteration, uint32_t stream) {
    return RngKey{seed, r.pixel, r.sample, r.vertex, iteration, stream};
}

/// The MIS weight of a sample drawn with pdf `a` against a strategy with pdf `b`.
inline float PowerHeuristic(float a, float b) {
    // Veach 1997, eq. 9.13 with beta = 2.
    if (std::isinf(a)) return 1;
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0 ? a2 / (a2 + b2) : 0;
}

/// A path or photon leaving solid absorbing glass through the hit `h` (its ray runs along the
/// surface's outward, winding-given normal) crossed the glass from its last vertex: Beer-Lambert,
/// exp(-α d) over that length d (Beer 1852), for closed, outward-wound objects not nested in
/// another.
inline void AbsorbInsideGlass(const SurfaceMaterial& m, const SurfaceHit& h, RayRecord* r) {
    const DielectricMaterial* glass = m.absorbing_dielectric();
    if (glass == nullptr || Dot(r->dir, h.ng) <= 0) return;
    r->beta *= glass->Transmittance(r->since_vertex + Length(h.p - r->origin), r->lambda);
}

/// The BSDF of the surface at `h` for `lambda`, which cannot tell reflection from transmission
/// otherwise than its facet does (Bsdf::SetGeometricNormal).
inline Bsdf BsdfAt(const SurfaceHit& h, SampledWavelengths* lambda) {
    Bsdf bsdf = h.material->MakeBsdf(h.ns, lambda, h.has_uv ? &h.uv : nullptr, h.footprint);
    bsdf.SetGeometricNormal(h.ng);
    return bsdf;
}

/// The cone of `r` (ray.h) as it leaves `h`, `t` from its origin: as wide as it arrived; a
/// non-specular (`scattered`) bounce widens its spread to at least kScatteredConeSpread, a specular
/// one or a straight pass keeps it (a mirror or a pane does not blur; the surfaces' curvature,
/// which Akenine-Möller et al. 2019 add, is left out). With levels of detail, the ray keeps the
/// surface's level up to LevelReach.
inline void CarryFootprint(RayRecord& r, const SurfaceHit& h, float t, bool scattered) {
    r.cone_width = ConeWidthAt(r, t);
    if (scattered) r.cone_spread = std::max(r.cone_spread, kScatteredConeSpread);
    r.origin_level = uint8_t(h.lod.level);
    r.level_reach = LevelReach(h.lod.error, r.cone_width, h.lod.coarsest_error);
}

/// The medium ray `r`, arriving at `h` along r.dir, travels in once it leaves toward `wi`. Through
/// a solid's surface (a refraction: it arrived on one side of the geometric normal and leaves on
/// the other) it goes into the solid's inside or back out to the air; solids do not nest (a ray
/// leaving one is outside all), and a solid's normals face out, as its absorption already assumes
/// (AbsorbInsideGlass). Anywhere else (a reflection, thin glass, any other material) it stays in
/// the medium it was in.
inline uint8_t MediumPast(const RayRecord& r, const SurfaceHit& h, const Vec3f& wi) {
    const uint8_t inside = h.material != nullptr ? h.material->medium_inside : kOutsideMedium;
    if (inside == kOutsideMedium) return r.medium;
    const float arriving = Dot(r.dir, h.ng), leaving = Dot(wi, h.ng);
    if (!(arriving * leaving > 0)) return r.medium;  // reflected
    return leaving < 0 ? inside : kOutsideMedium;
}

/// Carries `r`'s footprint and medium (MediumPast) off `h`, where it arrived along r.dir, into
/// `wi` and returns where the ray starts: off the surface by OffsetOrigin and, from a coarse
/// level, by LevelOffset along its normal.
inline Vec3f LeaveSurface(RayRecord& r, const SurfaceHit& h, const Vec3f& wi, float t,
                          bool scattered) {
    CarryFootprint(r, h, t, scattered);
    r.medium = MediumPast(r, h, wi);
    const Vec3f origin = OffsetOrigin(h.p, h.ng, wi);
    const float offset = LevelOffset(h.lod.error);
    if (offset == 0) return origin;  // full detail
    const Vec3f n = Normalize(h.ng);
    return origin + (Dot(n, wi) >= 0 ? n : -n) * offset;
}

/// Moves path or photon `r` on through the pass-through surface at `h` (thin glass: not a bounce,
/// so neither its depth nor its direction changes), toward `wi`. False if nothing is left of it.
/// The ray goes on along its line from just past the pane, as shadow rays do
/// (CameraPaths::ShadowThroughBrick), without LevelOffset: what lies within a level's error
/// behind a pane (the lead cames a few millimetres behind the glass) is there for it as for the
/// rays that cross at full detail. Skipped, it let 4 % more paths through the abbey's windows at
/// level 1, and the north aisle rendered 1.5 % too bright (docs/render.md, "Levels of detail").
/// Its own level's copy of the pane is behind it, and near its origin it sees no other level's
/// (LevelReach).
inline bool PassThrough(RayRecord& r, const SurfaceHit& h, const Vec3f& wi) {
    if (r.beta.IsZero()) return false;
    const float t = Length(h.p - r.origin);
    r.since_vertex += t;
    CarryFootprint(r, h, t, /*scattered=*/false);
    r.origin = OffsetOrigin(h.p, h.ng, wi);
    r.t_max = kInfinity;
    return true;
}

/// Bounces path or photon `r` at `h` into direction `wi` (sampled from a `specular` lobe or not):
/// its next vertex. False if nothing is left of it.
inline bool Bounce(RayRecord& r, const SurfaceHit& h, const Vec3f& wi, bool specular) {
    if (r.beta.IsZero()) return false;
    r.origin = LeaveSurface(r, h, wi, Length(h.p - r.origin), !specular);
    r.since_vertex = 0;
    r.dir = wi;
    r.t_max = kInfinity;
    r.depth += 1;
    return true;
}

/// One pass over the bricks at `detail` (pinned through `scheduler`, so through the pager when
/// paging) calling `visit(mesh, t, b)` for every triangle t of brick b whose material passes
/// `want`. A triangle stored in several bricks (it crosses cells) is visited once: in the brick
/// whose cell holds its centroid. At ScanDetail::kCoarsest the triangles are a level's, which
/// may differ from the full surface by the level's error and, at a cell's face, miss or repeat a
/// sliver: fit for what only guides sampling under a density that stays consistent with the set
/// (the portals), not for light sources. In a distributed render, this process's bricks only
/// (StreamScheduler::ForEachBrick). Errors: a brick that cannot be pinned. Call from the render's
/// thread, not during a Drain.
Status ForEachOwnedTriangle(
    const RenderScene& scene, StreamScheduler& scheduler, ScanDetail detail,
    const std::function<bool(const SurfaceMaterial&)>& want,
    const std::function<void(const ResidentMesh&, size_t, uint32_t)>& visit);

/// What every process of a distributed render found in its own bricks (ForEachOwnedTriangle):
/// `mine`, records with a `brick` field found brick by brick in order, put together in every
/// process in the order one process finds them (by brick; within a brick, in its finder's order).
/// Collective. Errors: the gather's.
template <typename Found>
StatusOr<std::vector<Found>> GatherInBrickOrder(RankGroup& ranks, std::span<const Found> mine) {
    NAVE_ASSIGN_OR_RETURN(const std::vector<std::byte> all,
                          ranks.GatherEverywhere(std::as_bytes(mine)));
    NAVE_ASSIGN_OR_RETURN(std::vector<Found> found,
                          RecordsFromBytes<Found>(all, "gathered from the processes"));
    std::stable_sort(found.begin(), found.end(),
                     [](const Found& a, const Found& b) { return a.brick < b.brick; });
    return found;
}

/// Where `r`'s segment in `brick` starts. At a coarse level the segment reaches back past the
/// cell's face by kLevelOverlap times the level's error: where the ray crossed from a brick at
/// another level, the two levels' copies of a surface cut by the face lie up to their errors apart,
/// and a ray passing between them would slip through the surface. Hits there are only looked for
/// once the brick before missed (bricks are traced in order), so a surface is never met twice.
inline float SegmentStart(const RayRecord& r, const ResidentBrick& brick) {
    const LevelOfDetail& lod = brick.lod();
    if (r.t_enter == 0 || lod.level == 0) return r.t_enter;
    return std::max(r.t_enter - kLevelOverlap * lod.error, 0.f);
}

/// Where `r`'s segment in `brick` ends: past the cell's face by the slack of SegmentEndWithSlack
/// and, at a coarse level, kLevelOverlap times its error (SegmentStart: the same crossing seen
/// from the brick before).
inline float SegmentEnd(const RayRecord& r, const ResidentBrick& brick) {
    return std::min(SegmentEndWithSlack(r.t_exit) + kLevelOverlap * brick.lod().error, r.t_max);
}

/// Traces a path or photon ray `r` inside brick `b` (pinned as `brick`) from its segment there. At
/// each hit, `shade(r, hit)` scatters the ray in place and returns whether it goes on. A ray that
/// goes on inside the cell is traced on at once, without queueing; one whose next segment lies in
/// another brick is sent to `out`; one that leaves the model goes to `escape(r)`. Every stretch
/// [t0, t1] of the ray it crosses without meeting a surface (to a hit, to the next brick's
/// segment, or to the end) is first given to `fly(r, t0, t1)`, which returns false if the ray
/// ended or went on elsewhere on the way (a scattering in a medium).
template <typename Fly, typename Shade, typename Escape>
void TraceInBrick(RayRecord& r, uint32_t b, const ResidentBrick& brick,
                  const StreamScheduler& scheduler, RayOutbox& out, Fly&& fly, Shade&& shade,
                  Escape&& escape) {
    // Sends `r`, whose next stop Route found (`next`), on from t = `from`.
    const auto go_on = [&](uint32_t next, float from) {
        if (!fly(r, from, next == store::kNoBrick ? r.t_max : r.t_enter)) return false;
        if (next == store::kNoBrick) {
            escape(r);
            return false;
        }
        if (next == b) return true;  // still in this brick: keep tracing without queueing
        out.Send(next, b, r);
        return false;
    };
    for (;;) {
        const float t1 = SegmentEnd(r, brick);
        ++out.counts.segments_traced;
        BrickHit hit;
        if (!brick.Intersect(r.origin, r.dir, SegmentStart(r, brick), t1, &hit)) {
            const float from = r.t_enter;
            go_on(scheduler.Route(r, r.t_exit, b), from);  // never b again: Route skips it
            return;
        }
        if (!fly(r, r.t_enter, hit.t)) return;
        if (!shade(r, hit)) return;
        ++out.counts.rays;
        if (!go_on(scheduler.Route(r, 0, store::kNoBrick), 0)) return;
    }
}

}  // namespace nave::render
