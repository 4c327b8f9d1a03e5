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

/// How far off its surface, along the normal, a ray leaving a level of detail starts. Each level's
/// copy of that surface lies within its error of the full one; the ray's origin surface is within
/// `origin_error`, and the levels its footprint chooses near the origin within width /
/// kFootprintPerLevelError (at most the model's coarsest error). Started that far off, the ray
/// passes every copy in front of it; as it goes on, it rises t |cos theta| while the levels' errors
/// grow by spread t / kFootprintPerLevelError, which it outruns unless it leaves within 4 degrees
/// of grazing (kScatteredConeSpread / 2). Whatever lies nearer to the surface than that goes unseen
/// by this ray: detail below what its levels resolve. 0 without levels.
inline float LevelOffset(float origin_error, float width, float coarsest_error) {
    return origin_error + std::min(width / kFootprintPerLevelError, coarsest_error);
}

}  // namespace nave::render
