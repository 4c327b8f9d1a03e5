#pragma once
// Stanford PLY: ASCII, binary little and big endian. Faces are lists of any length (triangulated as
// in import/triangulate.h); `tristrips` elements (lists with -1 restarts, as 3D scanners write)
// become triangles with alternating winding; properties nave does not use (colours, confidence...)
// are read and ignored.
//
// Memory: faces index into the vertex element, which therefore must come first and is kept in
// memory (12 bytes per vertex, 24 with normals, 32 with texture coordinates). Faces stream.

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// Opens `path` and reads its header. Errors name the file and the header line.
StatusOr<std::unique_ptr<TriangleSource>> OpenPly(const std::filesystem::path& path);

}  // namespace nave::preprocess
