#pragma once
// The interface of nave's IFC plugin (libnave_ifc.so, built from preprocess/import/ifc/): IFC 2x3
// and IFC 4 building models read with IFC++ (Debian's libifcplusplus-dev), whose geometry converter
// turns their extrusions, B-reps and tessellations into triangle meshes with the openings cut out
// (Carve's CSG), in metres. In a plugin for the same reason as the CAD plugin (cad_plugin.h), and
// called in a child process (cad_importer.h): a damaged file can crash a library this large.

#include <filesystem>
#include <functional>
#include <vector>

#include "preprocess/import/cad_plugin.h"

namespace nave::preprocess {

/// Bumped whenever IfcPlugin's methods or the types they take change.
inline constexpr int kIfcPluginVersion = 1;

/// What an IFC material's name says (ifc_plugin.h's ReadIfc): glazing of windows, doors and
/// curtain-wall plates carries this word, so that one config pattern (`[materials."*glazing*"]`)
/// makes every pane of a building window glass and a portal.
inline constexpr const char* kIfcGlazingWord = "glazing";

class IfcPlugin {
  public:
    virtual ~IfcPlugin() = default;
    /// Reads `file` and calls `emit` for every product with geometry (walls, slabs, windows...),
    /// once per material, its triangles in metres (the file's length unit applied) in the model's
    /// frame, Z up as IFC is; `materials` is filled with one record per entity type and surface
    /// style: "IfcWall:Limestone" (the style's name) or "IfcWall" (no style), with the style's
    /// colour; transparent items of IfcWindow, IfcDoor and IfcPlate are their glazing,
    /// "IfcWindow glazing:Glass". IfcSpace, openings and virtual elements are not rendered (their
    /// volumes are rooms and holes, not surfaces). The summary's `by_kind` counts triangles per
    /// entity type. Errors: DataLoss naming the file when it holds no IFC entity (not IFC, or
    /// damaged) or the library fails on it.
    virtual StatusOr<CadReadSummary> ReadIfc(
        const std::filesystem::path& file, const std::function<Status(IndexedMesh&&)>& emit,
        std::vector<store::MaterialRecord>& materials) const = 0;
};

/// Loads libnave_ifc.so (once). Unsupported naming the package when nave was built without IFC++.
StatusOr<const IfcPlugin*> LoadIfcPlugin();

/// True when this build has the IFC plugin (IFC++ was found).
bool IfcPluginBuilt();

}  // namespace nave::preprocess
