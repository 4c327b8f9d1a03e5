// The brick tree: Locate and Traverse against brute force over the leaf cells, and Validate's
// refusals.

#include "store/brick_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

namespace nave::store {
namespace {

// A random kd-tree over `bounds`: random axes and split positions, about a quarter of the leaves
// empty, brick ids shuffled so that they do not follow the node order.
BrickTree RandomTree(std::mt19937& rng, const Bounds3f& bounds, int depth, uint32_t* brick_count) {
    std::vector<BrickTreeNode> nodes;
    std::vector<uint32_t> leaves;
    std::uniform_real_distribution<float> unit(0.15f, 0.85f);
    std::bernoulli_distribution empty(0.25), stop(0.2);
    auto build = [&](auto&& self, Bounds3f box, int level) -> uint32_t {
        const uint32_t index = uint32_t(nodes.size());
        nodes.emplace_back();
        if (level == depth || (level > 1 && stop(rng))) {
            nodes[index].axis = 3;
            nodes[index].brick = empty(rng) ? kNoBrick : 0;
            if (nodes[index].brick != kNoBrick) leaves.push_back(index);
            return index;
        }
        const int axis = std::uniform_int_distribution<int>(0, 2)(rng);
        const float split = box.min[axis] + (box.max[axis] - box.min[axis]) * unit(rng);
        Bounds3f below = box, above = box;
        below.max[axis] = split;
        above.min[axis] = split;
        const uint32_t b = self(self, below, level + 1);
        const uint32_t a = self(self, above, level + 1);
        nodes[index].axis = uint8_t(axis);
        nodes[index].split = split;
        nodes[index].child[0] = b;
        nodes[index].child[1] = a;
        return index;
    };
    build(build, bounds, 0);
    std::vector<uint32_t> ids(leaves.size());
    for (uint32_t i = 0; i < ids.size(); ++i) ids[i] = i;
    std::shuffle(ids.begin(), ids.end(), rng);
    for (size_t i = 0; i < leaves.size(); ++i) nodes[leaves[i]].brick = ids[i];
    *brick_count = uint32_t(leaves.size());
    return BrickTree(bounds, std::move(nodes));
}

// The parametric interval of the ray inside `box`, clipped to [t_min, t_max] (empty if lo > hi).
// Boxes are closed; computed in double so it serves as the reference.
std::pair<double, double> Clip(const Bounds3f& box, const Vec3f& o, const Vec3f& d, double t_min,
                               double t_max) {
    double lo = t_min, hi = t_max;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
            if (o[a] < box.min[a] || o[a] > box.max[a]) return {1, 0};
            continue;
        }
        double t0 = (double(box.min[a]) - o[a]) / d[a], t1 = (double(box.max[a]) - o[a]) / d[a];
        if (t0 > t1) std::swap(t0, t1);
        lo = std::max(lo, t0);
        hi = std::min(hi, t1);
    }
    return {lo, hi};
}

TEST(BrickTree, LocateMatchesBruteForce) {
    std::mt19937 rng(7);
    const Bounds3f bounds({-3, -2, -1}, {5, 4, 2});
    for (int trial = 0; trial < 20; ++trial) {
        uint32_t bricks = 0;
        const BrickTree tree = RandomTree(rng, bounds, 7, &bricks);
        ASSERT_TRUE(tree.Validate(bricks).ok());
        const std::vector<Bounds3f> cells = tree.BrickCells(bricks);
        std::uniform_real_distribution<float> x(-4, 6), y(-3, 5), z(-2, 3);
        for (int i = 0; i < 500; ++i) {
            const Vec3f p{x(rng), y(rng), z(rng)};
            uint32_t expected = kNoBrick;
            for (uint32_t b = 0; b < bricks; ++b) {
                // Half-open cells: the upper cell owns its lower face (the outer box is closed).
                bool inside = true;
                for (int a = 0; a < 3; ++a) {
                    inside &= p[a] >= cells[b].min[a] &&
                              (p[a] < cells[b].max[a] ||
                               (p[a] == bounds.max[a] && cells[b].max[a] == bounds.max[a]));
                }
                if (inside) {
                    EXPECT_EQ(expected, kNoBrick) << "cells overlap at " << p;
                    expected = b;
                }
            }
            EXPECT_EQ(tree.Locate(p), expected) << p;
        }
    }
}

// BricksOverlapping lists exactly the bricks whose closed cells overlap the closed box, whatever
// its size: points, boxes within a cell, boxes across many and boxes partly outside the tree.
TEST(BrickTree, BricksOverlappingMatchesBruteForce) {
    std::mt19937 rng(11);
    const Bounds3f bounds({-3, -2, -1}, {5, 4, 2});
    for (int trial = 0; trial < 20; ++trial) {
        uint32_t bricks = 0;
        const BrickTree tree = RandomTree(rng, bounds, 7, &bricks);
        ASSERT_TRUE(tree.Validate(bricks).ok());
        const std::vector<Bounds3f> cells = tree.BrickCells(bricks);
        std::uniform_real_distribution<float> x(-4, 6), y(-3, 5), z(-2, 3), size(0, 3);
        std::vector<uint32_t> found;
        for (int i = 0; i < 300; ++i) {
            const Vec3f lo{x(rng), y(rng), z(rng)};
            const float s = i % 3 == 0 ? 0.f : size(rng);
            const Bounds3f box(lo, lo + Vec3f(s, s * 0.5f, s * 0.25f));
            std::vector<uint32_t> expected;
            for (uint32_t b = 0; b < bricks; ++b) {
                if (cells[b].Overlaps(box)) expected.push_back(b);
            }
            tree.BricksOverlapping(box, &found);
            std::sort(found.begin(), found.end());
            EXPECT_EQ(found, expected) << "box " << box.min << " - " << box.max;
        }
    }
}

TEST(BrickTree, TraverseVisitsEveryCrossedCellOnceFrontToBack) {
    std::mt19937 rng(11);
    const Bounds3f bounds({0, 0, 0}, {10, 6, 4});
    std::uniform_real_distribution<float> ox(-3, 13), oy(-3, 9), oz(-3, 7), dir(-1, 1),
        t_start(0, 2);
    std::bernoulli_distribution axis_aligned(0.15);
    int rays_with_hits = 0;
    for (int trial = 0; trial < 10; ++trial) {
        uint32_t bricks = 0;
        const BrickTree tree = RandomTree(rng, bounds, 8, &bricks);
        const std::vector<Bounds3f> cells = tree.BrickCells(bricks);
        for (int r = 0; r < 400; ++r) {
            const Vec3f o{ox(rng), oy(rng), oz(rng)};
            Vec3f d{dir(rng), dir(rng), dir(rng)};
            if (axis_aligned(rng)) d[r % 3] = 0;  // rays parallel to split planes
            if (Length(d) < 1e-3f) continue;
            d = Normalize(d);
            const float t_min = r % 4 == 0 ? t_start(rng) : 0.f;
            const float t_max = r % 5 == 0 ? 6.f : std::numeric_limits<float>::infinity();

            std::vector<std::tuple<uint32_t, float, float>> visited;
            tree.Traverse(o, d, t_min, t_max, [&](uint32_t b, float t0, float t1) {
                visited.emplace_back(b, t0, t1);
                return true;
            });
            std::vector<int> count(bricks, 0);
            float last_enter = -std::numeric_limits<float>::infinity();
            for (const auto& [b, t0, t1] : visited) {
                ASSERT_LT(b, bricks);
                EXPECT_EQ(++count[b], 1) << "brick " << b << " visited twice";
                EXPECT_GE(t0, last_enter - 1e-4f) << "not front to back";
                last_enter = t0;
                const auto [lo, hi] = Clip(cells[b], o, d, t_min, t_max);
                EXPECT_LE(lo, hi + 1e-4) << "visited brick " << b << " that the ray misses";
                EXPECT_NEAR(t0, lo, 1e-3 * (1 + std::fabs(lo)));
                if (std::isfinite(hi)) {
                    EXPECT_NEAR(t1, hi, 1e-3 * (1 + std::fabs(hi)));
                }
            }
            for (uint32_t b = 0; b < bricks; ++b) {
                const auto [lo, hi] = Clip(cells[b], o, d, t_min, t_max);
                if (hi - lo > 1e-3) {
                    EXPECT_EQ(count[b], 1)
                        << "ray crosses brick " << b << " over [" << lo << ", " << hi << "]";
                }
            }
            rays_with_hits += visited.empty() ? 0 : 1;
        }
    }
    EXPECT_GT(rays_with_hits, 1000);  // the test exercised real traversals
}

TEST(BrickTree, TraverseStopsWhenTheVisitorSaysSo) {
    std::mt19937 rng(3);
    uint32_t bricks = 0;
    const BrickTree tree = RandomTree(rng, Bounds3f({0, 0, 0}, {1, 1, 1}), 6, &bricks);
    int calls = 0;
    tree.Traverse({-1, 0.5f, 0.5f}, {1, 0, 0}, 0, 10,
                  [&](uint32_t, float, float) { return ++calls < 2; });
    EXPECT_EQ(calls, 2);
}

TEST(BrickTree, ValidateRefusesBrokenTrees) {
    const Bounds3f box({0, 0, 0}, {1, 1, 1});
    auto leaf = [](uint32_t brick) {
        BrickTreeNode n;
        n.brick = brick;
        return n;
    };
    auto split = [](uint8_t axis, float at, uint32_t a, uint32_t b) {
        BrickTreeNode n;
        n.axis = axis;
        n.split = at;
        n.child[0] = a;
        n.child[1] = b;
        return n;
    };
    EXPECT_TRUE(BrickTree(box, {split(0, 0.5f, 1, 2), leaf(0), leaf(1)}).Validate(2).ok());
    EXPECT_EQ(BrickTree(box, {}).Validate(0).code(), StatusCode::kDataLoss);
    Status s = BrickTree(box, {split(0, 0.5f, 1, 5), leaf(0), leaf(1)}).Validate(2);
    EXPECT_NE(s.message().find("child 5 out of range"), std::string::npos) << s.message();
    s = BrickTree(box, {split(0, 0.5f, 1, 1), leaf(0)}).Validate(2);
    EXPECT_NE(s.message().find("reached twice"), std::string::npos) << s.message();
    s = BrickTree(box, {split(0, 0.5f, 1, 2), leaf(0), leaf(0)}).Validate(2);
    EXPECT_NE(s.message().find("brick 0 appears in two"), std::string::npos) << s.message();
    s = BrickTree(box, {split(0, 0.5f, 1, 2), leaf(0), leaf(7)}).Validate(2);
    EXPECT_NE(s.message().find("names brick 7"), std::string::npos) << s.message();
    s = BrickTree(box, {split(9, 0.5f, 1, 2), leaf(0), leaf(1)}).Validate(2);
    EXPECT_NE(s.message().find("axis 9"), std::string::npos) << s.message();
    s = BrickTree(box, {split(0, std::numeric_limits<float>::quiet_NaN(), 1, 2), leaf(0), leaf(1)})
            .Validate(2);
    EXPECT_NE(s.message().find("split plane"), std::string::npos) << s.message();
    // A chain deeper than Traverse's stack.
    std::vector<BrickTreeNode> nodes(141);
    for (uint32_t i = 0; i < 70; ++i) {
        nodes[2 * i] = split(0, 0.5f, 2 * i + 1, 2 * i + 2);
        nodes[2 * i + 1] = leaf(kNoBrick);
    }
    nodes[140] = leaf(0);
    s = BrickTree(box, nodes).Validate(1);
    EXPECT_NE(s.message().find("deeper than the limit 64"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace nave::store
