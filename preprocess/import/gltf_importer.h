#pragma once
// glTF 2.0 (.gltf + .bin, or .glb) through tinygltf. The default scene's node hierarchy is walked
// and each mesh primitive transformed to world space (normals by the inverse transpose). Materials
// keep their PBR factors (baseColor, emissive, metallic, roughness) and texture image names. glTF
// is in metres. Not streamed: the whole file is loaded (glTF models are meant for memory).

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

StatusOr<std::unique_ptr<TriangleSource>> OpenGltf(const std::filesystem::path& path);

}  // namespace nave::preprocess
