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

/// Where a ray may start meeting a level other than the one it left (or the same level of another
/// brick, simplified on its own): each level's surface lies within its error of the full one, so
/// near the origin the other level's copy of the surface just left may lie on either side of the
/// ray, up to the sum of both errors away along the normal; the ray, leaving at angle theta to
/// it, clears that sum once t |cos theta| exceeds it. `clearance_per_error` is 1 / |cos theta|,
/// at most kMaxClearancePerError (grazing rays). Whatever lies nearer than the two errors is
/// below what both levels resolve anyway.
inline constexpr float kMaxClearancePerError = 10.f;
inline float ClearancePerError(float cos_theta) {
    return 1.f / std::max(std::abs(cos_theta), 1.f / kMaxClearancePerError);
}
inline float LevelClearance(float origin_error, float level_error, float clearance_per_error) {
    return (origin_error + level_error) * clearance_per_error;
}

}  // namespace nave::render
