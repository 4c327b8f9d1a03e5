#pragma once
// Every other format Assimp reads (FBX, DAE, 3DS, ...). Loaded whole, triangulated, node transforms
// baked.

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// True if Assimp has an importer for `path`'s extension.
bool AssimpSupports(const std::filesystem::path& path);
StatusOr<std::unique_ptr<TriangleSource>> OpenWithAssimp(const std::filesystem::path& path);

}  // namespace nave::preprocess
