#include "src/render/bricks/brick_walk.h"

namespace nave::render {

BrickSegment NextBrick(const store::BrickTree& tree, const Vec3f& origin, const Vec3f& dir,
                       float from_t, float t_max, uint32_t current) {
    BrickSegment seg;
    if (!(from_t < t_max)) return seg;
    tree.Traverse(origin, dir, from_t, t_max, [&](uint32_t brick, float t0, float t1) {
        // Cells are convex: a ray never comes back to the cell it left, so skipping `current` is
        // exact. A segment of zero length past from_t (a corner touched) holds nothing the
        // neighbours do not.
        if (brick == current || t1 <= from_t) return true;
        seg.brick = brick;
        seg.t_enter = std::max(t0, from_t);
        seg.t_exit = t1;
        return false;
    });
    return seg;
}

StatusOr<bool> TraceNearest(BrickSource& source, const Vec3f& origin, const Vec3f& dir, float t_min,
                            float t_max, BrickHit* hit, uint32_t* brick) {
    uint32_t current = store::kNoBrick;
    float from = t_min;
    // The first cell may contain the origin: start with every brick allowed.
    for (;;) {
        BrickSegment seg = NextBrick(source.tree(), origin, dir, from, t_max, current);
        if (seg.brick == store::kNoBrick) return false;
        NAVE_ASSIGN_OR_RETURN(BrickHandle h, source.Acquire(seg.brick));
        if (h->Intersect(origin, dir, seg.t_enter, std::min(SegmentEndWithSlack(seg.t_exit), t_max),
                         hit)) {
            *brick = seg.brick;
            return true;
        }
        current = seg.brick;
        from = seg.t_exit;
    }
}

}  // namespace nave::render
