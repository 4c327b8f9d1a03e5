#include "store/brick_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nave::store {

BrickTree::BrickTree(Bounds3f bounds, std::vector<BrickTreeNode> nodes)
    : bounds_(bounds), nodes_(std::move(nodes)) {}

Status BrickTree::Validate(uint32_t brick_count) const {
    if (nodes_.empty()) return DataLossError("brick tree has no nodes");
    std::vector<uint8_t> seen_brick(brick_count, 0);
    std::vector<uint8_t> seen_node(nodes_.size(), 0);
    struct Item {
        uint32_t node;
        uint32_t depth;
    };
    std::vector<Item> stack{{0, 0}};
    while (!stack.empty()) {
        const auto [n, depth] = stack.back();
        stack.pop_back();
        if (seen_node[n])
            return DataLossError("brick tree node {} is reached twice (a cycle or shared child)",
                                 n);
        seen_node[n] = 1;
        // Traverse keeps at most one pending node per level on a fixed stack.
        if (depth >= kMaxDepth) {
            return DataLossError("brick tree node {} is at depth {}, deeper than the limit {}", n,
                                 depth, kMaxDepth);
        }
        const BrickTreeNode& node = nodes_[n];
        if (node.IsLeaf()) {
            if (node.brick == kNoBrick) continue;
            if (node.brick >= brick_count) {
                return DataLossError(
                    "brick tree leaf {} names brick {} but the store has {} bricks", n, node.brick,
                    brick_count);
            }
            if (seen_brick[node.brick])
                return DataLossError("brick {} appears in two brick tree leaves", node.brick);
            seen_brick[node.brick] = 1;
            continue;
        }
        if (node.axis > 3)
            return DataLossError("brick tree node {} has axis {} (expected 0..3)", n, node.axis);
        if (!std::isfinite(node.split)) {
            return DataLossError("brick tree node {} has a split plane at {}", n, node.split);
        }
        for (uint32_t c : node.child) {
            if (c == 0 || c >= nodes_.size()) {
                return DataLossError("brick tree node {} has child {} out of range [1, {})", n, c,
                                     nodes_.size());
            }
            stack.push_back({c, depth + 1});
        }
    }
    return Status::Ok();
}

void BrickTree::BricksOverlapping(const Bounds3f& box, std::vector<uint32_t>* out) const {
    out->clear();
    if (nodes_.empty() || !bounds_.Overlaps(box)) return;
    uint32_t stack[kMaxDepth + 1];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BrickTreeNode& n = nodes_[stack[--top]];
        if (n.IsLeaf()) {
            if (n.brick != kNoBrick) out->push_back(n.brick);
            continue;
        }
        // Below the plane: [.., split); above: [split, ..]. Closed tests: a box touching the plane
        // is on both sides.
        if (box.min[n.axis] <= n.split && top <= int(kMaxDepth)) stack[top++] = n.child[0];
        if (box.max[n.axis] >= n.split && top <= int(kMaxDepth)) stack[top++] = n.child[1];
    }
}

uint32_t BrickTree::Locate(const Vec3f& p) const {
    if (nodes_.empty() || !bounds_.Contains(p)) return kNoBrick;
    uint32_t n = 0;
    while (!nodes_[n].IsLeaf()) {
        const BrickTreeNode& node = nodes_[n];
        n = node.child[p[node.axis] >= node.split ? 1 : 0];
    }
    return nodes_[n].brick;
}

std::vector<Bounds3f> BrickTree::BrickCells(uint32_t brick_count) const {
    std::vector<Bounds3f> cells(brick_count);
    for (const auto& [node, box] : LeafCells()) {
        const uint32_t brick = nodes_[node].brick;
        if (brick != kNoBrick && brick < brick_count) cells[brick] = box;
    }
    return cells;
}

std::vector<std::pair<uint32_t, Bounds3f>> BrickTree::LeafCells() const {
    std::vector<std::pair<uint32_t, Bounds3f>> leaves;
    if (nodes_.empty()) return leaves;
    std::vector<std::pair<uint32_t, Bounds3f>> stack{{0, bounds_}};
    while (!stack.empty()) {
        auto [n, box] = stack.back();
        stack.pop_back();
        const BrickTreeNode& node = nodes_[n];
        if (node.IsLeaf()) {
            leaves.emplace_back(n, box);
            continue;
        }
        Bounds3f below = box, above = box;
        below.max[node.axis] = node.split;
        above.min[node.axis] = node.split;
        stack.push_back({node.child[0], below});
        stack.push_back({node.child[1], above});
    }
    std::sort(leaves.begin(), leaves.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    return leaves;
}

void BrickTree::Traverse(const Vec3f& origin, const Vec3f& dir, float t_min, float t_max,
                         const std::function<bool(uint32_t, float, float)>& visit) const {
    if (nodes_.empty()) return;
    // Clip the ray to the root box, then walk the kd-tree front to back with an explicit stack.
    float t0, t1;
    if (!ClipRayToBounds(bounds_, origin, dir, t_min, t_max, &t0, &t1)) return;
    struct Item {
        uint32_t node;
        float t0, t1;
    };
    Item stack[kMaxDepth];
    int top = 0;
    stack[top++] = {0, t0, t1};
    while (top > 0) {
        Item item = stack[--top];
        uint32_t n = item.node;
        float a = item.t0, b = item.t1;
        while (!nodes_[n].IsLeaf()) {
            const BrickTreeNode& node = nodes_[n];
            const int axis = node.axis;
            const float o = origin[axis];
            const float d = dir[axis];
            // The child that holds the ray's start (ties go to the upper cell, as in Locate, unless
            // the ray moves downward from the plane).
            const bool start_above = o > node.split || (o == node.split && d >= 0);
            uint32_t first = node.child[start_above ? 1 : 0];
            uint32_t second = node.child[start_above ? 0 : 1];
            float t_split = d != 0 ? (node.split - o) / d : std::numeric_limits<float>::infinity();
            if (t_split > b || t_split <= 0) {
                n = first;
            } else if (t_split < a) {
                n = second;
            } else {
                NAVE_CHECK_LT(top, int(kMaxDepth)) << "brick tree deeper than Validate allows";
                stack[top++] = {second, t_split, b};
                n = first;
                b = t_split;
            }
        }
        uint32_t brick = nodes_[n].brick;
        if (brick != kNoBrick && !visit(brick, a, b)) return;
    }
}

}  // namespace nave::store
