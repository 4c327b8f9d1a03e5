#pragma once
// Which level of detail of a brick a ray is traced against (docs/render.md, "Levels of detail").
// Christensen et al. 2003 ("Ray differentials and multiresolution geometry caching for distribution
// ray tracing in complex scenes", §4) trace each ray against the coarsest tessellation whose
// detail its footprint cannot resolve; nave's footprint is the ray cone of RayRecord (Amanatides
// 1984, "Ray tracing with cones"; Akenine-Möller et al. 2019, Ray Tracing Gems ch. 20). The choice
// depends on the ray alone, never on what is resident, so images do not depend on the budget.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "src/render/stream/ray.h"

namespace nave::render {

/// A level may serve a ray whose footprint is at least this many times its error: the coarse
/// surface then lies within a fraction of the footprint of the full one, finer than the ray can
/// tell apart (Christensen et al. 2003 pick the tessellation whose micropolygons match the
/// footprint). Measured against full detail in docs/render.md, "Levels of detail".
inline constexpr float kFootprintPerLevelError = 2.f;

/// How wide a cone becomes at a non-specular scattering, in radians: a diffuse or glossy bounce
/// sends a path into one direction of a wide lobe, and its footprint is that of one sample among
/// many (Christensen et al. 2003, §3.2: the differential of a distribution ray is the lobe's
/// solid angle divided by the number of rays; a pixel's paths sample the lobe many times over).
/// 1/8 rad is the lobe of a cosine hemisphere (2π sr) shared by ~400 samples.
inline constexpr float kScatteredConeSpread = 0.125f;

/// Whether `r` may be traced against coarse levels: every ray but a path ray whose cone is still
/// its pixel's (a camera ray, or one that has since only crossed thin glass or met mirrors).
/// Christensen's rule assumes a coarse tessellation covers what the fine one covers, as it does
/// for smooth surfaces; simplification within an error does not keep that for thin parts (it
/// thins tracery, colonnettes and mullions), and a pixel's value is the mean of what covers it.
/// On the detail-30 abbey (nave view, 120x80, max_depth 1, against full detail) camera rays on
/// coarse levels saw the windows' tracery thinner and brightened the image by 7 %; kept at full
/// detail, +1.2 %, and +0.4 % at max_depth 10, within two seeds' spread (docs/render.md, "Levels
/// of detail"). Past a diffuse or glossy bounce a ray stands for one direction of a lobe that a
/// pixel's paths sample many times (kScatteredConeSpread): no one part's coverage decides it.
inline bool UsesLevels(const RayRecord& r) {
    return r.kind != kPathRay || r.cone_spread >= kScatteredConeSpread;
}

/// The coarsest of `count` levels (errors finest first, errors[0] = 0, a missing level +inf) that
/// a footprint `width` wide may use.
inline uint32_t ChooseLevel(const float* errors, uint32_t count, float width) {
    uint32_t level = 0;
    for (uint32_t l = 1; l < count; ++l) {
        if (errors[l] * kFootprintPerLevelError <= width) level = l;
    }
    return level;
}

/// How far past a cell's faces a brick at a coarse level is traced, in units of its error: the ray
/// may cross a face between two levels' copies of a surface, up to the sum of their errors apart
/// along the surface's normal, which along a ray at 75 degrees from it is about four times that.
inline constexpr float kLevelOverlap = 4.f;

/// The footprint of `r` at ray parameter t.
inline float ConeWidthAt(const RayRecord& r, float t) { return r.cone_width + r.cone_spread * t; }

/// How far along a ray leaving a level of detail it keeps that level in every brick it enters, in
/// units of the distance between its surface's copies near the origin. The copies at the levels
/// its footprint would soon choose lie within `origin_error` plus their errors of the copy it
/// leaves, on either side, and those errors are at most width / kFootprintPerLevelError (and the
/// model's coarsest error). Past kLevelReach times their sum, the ray has risen above every copy
/// unless it leaves within 15 degrees of grazing, and from there on it outruns the levels'
/// growing errors likewise. Nothing is skipped on the way: near its origin, the ray sees its own
/// level's copy of every surface, only finer or coarser than its footprint would choose.
inline constexpr float kLevelReach = 4.f;

/// The distance along a ray leaving a surface of level error `origin_error` (0: full detail) with
/// footprint `width` within which it keeps that surface's level. 0 without levels.
inline float LevelReach(float origin_error, float width, float coarsest_error) {
    return kLevelReach * (origin_error + std::min(width / kFootprintPerLevelError, coarsest_error));
}

/// How far off its surface, along the normal, a ray leaving a coarse level starts, in units of
/// that level's error. Two bricks each hold the triangles crossing their common face and simplify
/// them apart, so near a face even one level's copies of a surface in the two bricks lie up to
/// twice its error apart. Started on its facet (OffsetOrigin's rounding margin only), a ray could
/// start behind the neighbour's copy: a few in 10^5 crossed the coarse walls of the closed
/// thin-walled test room and let the sun in. A whole error off, rays skip what lies that near
/// their surface (+5 % on the abbey); half an error stops the crossing in the test room (none in
/// 480 000 paths), and the abbey's levels, which keep their areas, render within 1 % of full
/// detail on two of three views (docs/render.md, "Levels of detail").
inline constexpr float kOriginOffsetPerError = 0.5f;

/// The offset along the normal of a ray leaving a level whose error is `origin_error`.
inline float LevelOffset(float origin_error) { return kOriginOffsetPerError * origin_error; }

}  // namespace nave::render
