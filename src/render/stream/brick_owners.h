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

/// How the processes share the work on the slots every process holds (coarse levels kept
/// everywhere, docs/distributed.md): row r gives, for the rays process r's bricks send into those
/// slots, the fraction each process traces (row r sums to 1). `made[r]`: the work process r's
/// bricks make, their own and that of the rays they send into the shared slots, `shared[r]` of
/// it (at most made[r]), in any unit. A process above the mean hands its excess, at most all its
/// shared work, to the processes below the mean, in proportion to what each lacks; the others
/// keep their rays. Deterministic.
std::vector<std::vector<double>> SpreadOfSharedWork(const std::vector<double>& made,
                                                    const std::vector<double>& shared);

}  // namespace nave::render
