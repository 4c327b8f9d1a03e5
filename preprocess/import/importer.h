#pragma once
// Opening model files: the format is chosen by extension (and, for files without a known extension,
// by the first bytes), and several inputs become one merged source.

#include <filesystem>
#include <memory>
#include <vector>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// Opens one model file: .obj, .ply, .stl (streamed), .gltf/.glb (tinygltf), .step/.stp/.iges/.igs
/// (Open CASCADE, tessellated for a store grid step of `precision` metres, 0 for the default:
/// cad_importer.h), anything Assimp reads. Errors: NotFound, Unsupported (unknown format, naming
/// the extension and the formats nave reads; a DWG file, naming DXF as the way in).
StatusOr<std::unique_ptr<TriangleSource>> OpenModel(const std::filesystem::path& path,
                                                    double precision = 0);

/// Opens every input and merges them (material names made unique).
StatusOr<std::unique_ptr<TriangleSource>> OpenModels(
    const std::vector<std::filesystem::path>& paths, double precision = 0);

}  // namespace nave::preprocess
