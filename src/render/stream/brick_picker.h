#pragma once
// Which brick the scheduler drains next. The pager decides in every render (pager.h: the fullest
// resident brick first, weighing loads); a BrickPicker overrides it, for the tests that check that
// the image does not depend on the order in which bricks are processed.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "src/render/bricks/brick_source.h"

namespace nave::render {

/// The scheduling policy: which brick to process next, given the rays waiting in every brick's
/// queue (indexed by brick id; never called with all queues empty). Return a brick with waiting
/// rays. Called from the scheduler thread only. Empty: the pager's choice.
using BrickPicker =
    std::function<uint32_t(const std::vector<size_t>& waiting, const BrickSource& source)>;

/// The origin paper's policy without residency: the most rays waiting, lowest id on ties.
inline uint32_t PickFullestBrick(const std::vector<size_t>& waiting, const BrickSource&) {
    return uint32_t(std::max_element(waiting.begin(), waiting.end()) - waiting.begin());
}

}  // namespace nave::render
