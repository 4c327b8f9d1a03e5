#pragma once
// Wavefront OBJ (+ MTL), read as a stream in one forward pass. Polygons are triangulated
// (import/triangulate.h: fans when convex, ear clipping when concave), negative (relative) indices
// are resolved, CRLF lines are accepted.
//
// Memory: OBJ faces index into vertex, texture-coordinate and normal arrays that may appear
// anywhere before them, so those arrays are kept and grow with the file (12 bytes per v and vn, 8
// per vt): inherent to the format. Faces themselves are never kept. memory_bytes() reports the
// arrays for the budget.

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// Opens `path` for streaming. The MTL libraries it names are read when their `mtllib` line is
/// reached.
StatusOr<std::unique_ptr<TriangleSource>> OpenObj(const std::filesystem::path& path);

}  // namespace nave::preprocess
