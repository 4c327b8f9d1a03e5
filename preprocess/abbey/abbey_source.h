#pragma once
// The procedural abbey as a TriangleSource: its parts (abbey_plan.h) generated on several producer
// threads, each part into its own small bounded queue, and handed on part after part, so that `nave
// preprocess --generate abbey:detail=D` consumes it directly without an intermediate file, in
// constant memory whatever D. Deterministic: the same detail gives the same triangles in the same
// order, whatever the number of threads.

#include <memory>
#include <string>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// The abbey at `detail` (> 0; 1 is about a million triangles, see docs/abbey.md), generated on
/// `threads` producer threads (0: one per hardware thread).
std::unique_ptr<TriangleSource> MakeAbbeySource(double detail, int threads = 0);

/// Parses a generator spec "abbey" or "abbey:detail=D". Errors name the spec and the accepted
/// forms. `threads`: as for MakeAbbeySource.
StatusOr<std::unique_ptr<TriangleSource>> OpenGenerator(const std::string& spec, int threads = 0);

}  // namespace nave::preprocess
