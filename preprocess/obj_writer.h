#pragma once
// Writes any TriangleSource as OBJ + MTL (for looking at generated models in other tools),
// streaming: vertices are written per triangle (no sharing), so memory stays constant. Both files
// go through AtomicFile: an interrupted run leaves neither.

#include <filesystem>

#include "preprocess/triangle_source.h"
#include "src/core/status.h"

namespace nave::preprocess {

struct ObjWriteStats {
    uint64_t triangles = 0;
    uint64_t bytes = 0;
};

/// Writes `source` to `obj_path` and its materials to the same name with ".mtl".
StatusOr<ObjWriteStats> WriteObj(TriangleSource& source, const std::filesystem::path& obj_path);

}  // namespace nave::preprocess
