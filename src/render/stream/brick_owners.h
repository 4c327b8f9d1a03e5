#pragma once
// Which rank of a distributed render owns each brick (docs/distributed.md, "Bricks to ranks"): runs
// of bricks that are neighbours in the brick tree, so that most rays stay within their rank, each
// run about an equal share of the model's estimated memory, the measure of a brick's load and of
// the rays it stops.

#include <cstdint>
#include <vector>

#include "src/render/bricks/brick_source.h"

namespace nave::render {

/// The bricks of `source` as the leaves of its brick tree in depth-first order: the order in which
/// BrickOwners cuts runs.
std::vector<uint32_t> BricksDepthFirst(const BrickSource& source);
/// The rank (0 to `ranks` - 1) of every slot of `source` (every level of a brick goes with the
/// brick): the brick tree's leaves in depth-first order, cut into `ranks` runs of about equal
/// EstimatedResidentBytes at full detail. Deterministic: every rank computes the same.
std::vector<int> BrickOwners(const BrickSource& source, int ranks);
/// The same runs cut by `work` per brick (measured: the time its batches took, in any unit) in
/// place of the estimated memory: what re-balancing between passes uses. Bricks without work
/// weigh one unit. Deterministic for the same `work`.
std::vector<int> BrickOwnersByWork(const BrickSource& source, int ranks,
                                   const std::vector<uint64_t>& work);

}  // namespace nave::render
