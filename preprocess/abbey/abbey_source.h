#pragma once
// The procedural abbey as a TriangleSource: generated part by part on a producer thread into a
// small bounded queue, so that `nave preprocess --generate abbey:detail=D` consumes it directly
// without an intermediate file, in constant memory whatever D. Deterministic: the same detail gives
// the same triangles in the same order.

#include <memory>
#include <string>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// The abbey at `detail` (> 0; 1 is about a million triangles, see docs/abbey.md).
std::unique_ptr<TriangleSource> MakeAbbeySource(double detail);

/// Parses a generator spec "abbey" or "abbey:detail=D". Errors name the spec and the accepted
/// forms.
StatusOr<std::unique_ptr<TriangleSource>> OpenGenerator(const std::string& spec);

}  // namespace nave::preprocess
