#pragma once
// STEP and IGES files: boundary representations tessellated by Open CASCADE (through the CAD
// plugin, cad_plugin.h) in a child process, which writes each placed part's triangles to an
// unlinked temporary file as it goes; nave then streams them from there, one part at a time. So
// neither process holds the triangles of the whole model, and a library that crashes on a damaged
// file ends the child, not nave (as Assimp does: assimp_importer.h).

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// True for the extensions the CAD plugin reads: .step .stp .iges .igs (any case).
bool IsCadFile(const std::filesystem::path& path);

/// Reads `path` with Open CASCADE, tessellated for a store grid step of `precision` metres (0: the
/// model's diagonal / 2^20; cad_plugin.h says how the deflection follows it). The source's units
/// are "m". Errors: NotFound; Unsupported when nave was built without Open CASCADE; DataLoss
/// naming the file: with Open CASCADE's own words when it refuses the file, the signal when it
/// crashed on it, the time limit when it hung.
StatusOr<std::unique_ptr<TriangleSource>> OpenCad(const std::filesystem::path& path,
                                                  double precision);

}  // namespace nave::preprocess
