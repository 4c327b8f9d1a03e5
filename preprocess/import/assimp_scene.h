#pragma once
// Reading a model with Assimp inside the calling process. Assimp 5.2 aborts the process on some
// malformed files (its ai_assert calls abort()), so nave calls this only in a child process
// (assimp_importer.h); the in-process form exists for that child and for the fuzz target.

#include <filesystem>

#include "preprocess/import/model_wire.h"
#include "src/core/status.h"

namespace nave::preprocess {

/// Loads `path` whole, triangulated, node transforms baked into world-space meshes, points and
/// lines dropped. Errors: InvalidArgument with Assimp's message. May abort or crash on a malformed
/// file.
StatusOr<ImportedModel> ReadWithAssimpInProcess(const std::filesystem::path& path);

/// "Assimp 5.2.5", for messages.
std::string AssimpVersion();

}  // namespace nave::preprocess
