#include "src/render/stream/brick_owners.h"

#include <algorithm>

namespace nave::render {

namespace {

/// The slots' owners from runs of the leaves in depth-first order (each run a subtree or a few
/// neighbouring ones) of about equal `weight` per brick.
std::vector<int> OwnersOfRuns(const BrickSource& source, int ranks,
                              const std::vector<double>& weight) {
    const std::vector<uint32_t> order = BricksDepthFirst(source);
    double total = 0;
    for (uint32_t b : order) total += weight[b];
    std::vector<int> brick_owner(source.brick_count(), 0);
    double before = 0;
    for (uint32_t b : order) {
        // The rank whose share holds the middle of the brick's weight.
        const double middle = (before + 0.5 * weight[b]) / total;
        brick_owner[b] = std::clamp(int(middle * ranks), 0, ranks - 1);
        before += weight[b];
    }
    std::vector<int> owners(source.slot_count());
    for (uint32_t s = 0; s < owners.size(); ++s) owners[s] = brick_owner[source.BrickOfSlot(s)];
    return owners;
}

}  // namespace

std::vector<uint32_t> BricksDepthFirst(const BrickSource& source) {
    std::vector<uint32_t> order;
    const auto& nodes = source.tree().nodes();
    std::vector<uint32_t> stack;
    if (!nodes.empty()) stack.push_back(0);
    while (!stack.empty()) {
        const store::BrickTreeNode& node = nodes[stack.back()];
        stack.pop_back();
        if (node.IsLeaf()) {
            if (node.brick < source.brick_count()) order.push_back(node.brick);
            continue;
        }
        stack.push_back(node.child[1]);
        stack.push_back(node.child[0]);
    }
    return order;
}

std::vector<int> BrickOwners(const BrickSource& source, int ranks) {
    std::vector<double> weight(source.brick_count(), 0.0);
    for (uint32_t b = 0; b < source.brick_count(); ++b)
        weight[b] = double(source.EstimatedResidentBytes(b)) + 1.0;
    return OwnersOfRuns(source, ranks, weight);
}

std::vector<int> BrickOwnersByWork(const BrickSource& source, int ranks,
                                   const std::vector<uint64_t>& work) {
    std::vector<double> weight(source.brick_count(), 1.0);
    for (uint32_t b = 0; b < source.brick_count() && b < work.size(); ++b)
        weight[b] = double(work[b]) + 1.0;
    return OwnersOfRuns(source, ranks, weight);
}

std::vector<std::vector<double>> SpreadOfSharedWork(const std::vector<double>& made,
                                                    const std::vector<double>& shared) {
    const size_t n = made.size();
    std::vector<std::vector<double>> spread(n, std::vector<double>(n, 0.0));
    double total = 0;
    for (double m : made) total += m;
    const double mean = n > 0 ? total / double(n) : 0.0;
    double lacking = 0;
    for (double m : made) lacking += std::max(0.0, mean - m);
    for (size_t r = 0; r < n; ++r) {
        spread[r][r] = 1.0;
        const double excess = std::min(std::max(0.0, made[r] - mean), shared[r]);
        if (!(excess > 0 && lacking > 0 && shared[r] > 0)) continue;
        const double handed = excess / shared[r];  // the fraction of its shared rays it hands on
        spread[r][r] = 1.0 - handed;
        for (size_t d = 0; d < n; ++d) {
            if (d != r) spread[r][d] = handed * std::max(0.0, mean - made[d]) / lacking;
        }
    }
    return spread;
}

}  // namespace nave::render
