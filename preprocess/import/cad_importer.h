#pragma once
// STEP and IGES files (boundary representations tessellated by Open CASCADE through the CAD
// plugin, cad_plugin.h) and IFC files (building models meshed by IFC++ through the IFC plugin,
// ifc_plugin.h), read in a child process which writes each placed part's triangles to an
// unlinked temporary file as it goes; nave then streams them from there, one part at a time. So
// neither process holds the triangles of the whole model, and a library that crashes on a damaged
// file ends the child, not nave (as Assimp does: assimp_importer.h).

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// True for the extensions the CAD plugins read: .step .stp .iges .igs (any case), and .ifc when
/// this build has the IFC plugin (without it, .ifc goes to Assimp).
bool IsCadFile(const std::filesystem::path& path);

/// Reads `path` with Open CASCADE (STEP, IGES: tessellated for a store grid step of `precision`
/// metres, 0 for the model's diagonal / 2^20; cad_plugin.h says how the deflection follows it) or
/// IFC++ (IFC). The source's units are "m"; its content() names the format, the file's unit and
/// (IFC) the triangles per entity type. A file cut short (no END-ISO-10303-21; or IGES terminate
/// section at its end) is DataLoss before any library reads it. Errors: NotFound; Unsupported
/// when nave was built without the library; DataLoss naming the file: with the library's own
/// words when it refuses the file, the signal when it crashed on it, the time limit when it hung.
StatusOr<std::unique_ptr<TriangleSource>> OpenCad(const std::filesystem::path& path,
                                                  double precision);

}  // namespace nave::preprocess
