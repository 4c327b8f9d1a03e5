#pragma once
// Every other format Assimp reads (FBX, DAE, 3DS, ...). Loaded whole, triangulated, node transforms
// baked. Assimp runs in a child process (core/child_process.h) that sends the model back through a
// pipe: Assimp 5.2 aborts on some malformed files, and that must be an error, not nave's end.

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// True if Assimp has an importer for `path`'s extension.
bool AssimpSupports(const std::filesystem::path& path);
/// Reads `path` with Assimp in a child process. Errors: NotFound; InvalidArgument with Assimp's
/// message when it refuses the file; DataLoss naming the file and the signal when Assimp crashed on
/// it.
StatusOr<std::unique_ptr<TriangleSource>> OpenWithAssimp(const std::filesystem::path& path);

}  // namespace nave::preprocess
