#pragma once
// Moving a ray from brick to brick. A ray's segment in a brick is [t_enter, t_exit] of the brick's
// cell along the ray (BrickTree::Traverse). A brick may hold triangles that cross its cell (they
// are stored in every brick they overlap), so a hit is accepted only if its t lies in the segment:
// then the first brick along the ray that reports a hit holds the nearest one, because cells are
// disjoint and visited in order.

#include <cstdint>

#include "src/core/vecmath.h"
#include "src/render/bricks/brick_source.h"
#include "store/brick_tree.h"

namespace nave::render {

/// A ray's next stop: the brick and the segment of the ray inside its cell.
struct BrickSegment {
    uint32_t brick =
        store::kNoBrick;  ///< kNoBrick: the ray leaves the model (or reaches t_max) first
    float t_enter = 0, t_exit = 0;
};

/// The first non-empty cell along o + t d after `from_t` (t_exit > from_t), other than `current`.
/// Empty space costs nothing: the tree has no leaf brick there and nothing is loaded.
BrickSegment NextBrick(const store::BrickTree& tree, const Vec3f& origin, const Vec3f& dir,
                       float from_t, float t_max, uint32_t current);

/// Hits a brick accepts may lie this far (relative) beyond the segment's end: the float t of a cell
/// face and Embree's float t of a triangle on that face may round apart, and a triangle touching
/// the face from this side is stored in this brick only.
inline float SegmentEndWithSlack(float t_exit) { return t_exit + 1e-6f * (1.f + std::abs(t_exit)); }

/// The nearest hit along a ray across all bricks, walking them in order and acquiring each on the
/// way. Synchronous (one ray at a time): for tests, AOVs and benchmarks, not for the ray streams.
/// Returns false when the ray leaves the model; `brick` receives the brick of the hit.
StatusOr<bool> TraceNearest(BrickSource& source, const Vec3f& origin, const Vec3f& dir, float t_min,
                            float t_max, BrickHit* hit, uint32_t* brick);

}  // namespace nave::render
