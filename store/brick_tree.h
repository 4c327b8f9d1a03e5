#pragma once
// The kd-tree that locates bricks in space. Bricks are the leaves: disjoint boxes that together
// tile the model's bounds. A leaf may be empty (no brick: empty space, skipped by rays without
// loading anything). Because leaves are disjoint, a ray that visits leaves front to back finds the
// nearest hit in the first brick that reports a hit inside its own box. The tree is small (a few
// bytes per brick) and always resident.

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"

namespace nave::store {

inline constexpr uint32_t kNoBrick = 0xffffffffu;

/// One node: an interior split (axis 0..2, position, two children) or a leaf (brick id or
/// kNoBrick).
struct BrickTreeNode {
    uint8_t axis = 3;            ///< 0, 1, 2 for x, y, z splits; 3 for a leaf
    float split = 0.f;           ///< split plane position along `axis` (interior)
    uint32_t child[2] = {0, 0};  ///< below / above the plane (interior)
    uint32_t brick = kNoBrick;   ///< brick id (leaf)
    bool IsLeaf() const { return axis == 3; }
};

class BrickTree {
  public:
    BrickTree() = default;
    /// `nodes[0]` is the root; `bounds` is the box the root covers.
    BrickTree(Bounds3f bounds, std::vector<BrickTreeNode> nodes);

    /// Deepest tree Validate accepts (Traverse walks with a fixed stack of this many entries).
    static constexpr uint32_t kMaxDepth = 64;

    /// Checks the structure: child indices in range, no cycles, finite splits, depth < kMaxDepth,
    /// each brick id in [0, brick_count) at most once. Errors are DataLoss naming the node.
    Status Validate(uint32_t brick_count) const;

    const Bounds3f& bounds() const { return bounds_; }
    const std::vector<BrickTreeNode>& nodes() const { return nodes_; }

    /// The brick whose cell contains `p`, or kNoBrick (outside the model or in empty space). Points
    /// on a split plane belong to the upper cell.
    uint32_t Locate(const Vec3f& p) const;
    /// The cell (box) of every leaf, indexed by brick id (size brick_count; empty leaves are not
    /// listed).
    std::vector<Bounds3f> BrickCells(uint32_t brick_count) const;
    /// Every leaf, with a brick or empty, as (node index, cell), in node order (of a tree that
    /// Validate accepts).
    std::vector<std::pair<uint32_t, Bounds3f>> LeafCells() const;
    /// The non-empty bricks whose cells overlap `box` (closed: a box touching a split plane is on
    /// both sides), into `out` (cleared first).
    void BricksOverlapping(const Bounds3f& box, std::vector<uint32_t>* out) const;

    /// Calls `visit(brick, t_enter, t_exit)` for every non-empty cell the ray o + t d crosses
    /// within [t_min, t_max], front to back; stops early when `visit` returns false.
    void Traverse(
        const Vec3f& origin, const Vec3f& dir, float t_min, float t_max,
        const std::function<bool(uint32_t brick, float t_enter, float t_exit)>& visit) const;

  private:
    Bounds3f bounds_;
    std::vector<BrickTreeNode> nodes_;
};

}  // namespace nave::store
