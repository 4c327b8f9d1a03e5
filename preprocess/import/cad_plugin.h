#pragma once
// The interface of nave's CAD plugin (libnave_cad.so, built from preprocess/import/cad/): boundary
// representations (STEP, IGES) read with Open CASCADE and tessellated into triangle meshes. Open
// CASCADE is some 40 shared libraries (its data exchange pulls in its visualization too); linked
// into `nave`, every command would load them, so it lives in a plugin loaded when a CAD file is
// read, as OpenImageIO and OpenVDB do (src/imaging/oiio_plugin.h, src/volumes/vdb_plugin.h). The
// plugin is loaded by the parent and called in a child process (cad_importer.h), because a damaged
// file can crash a library this large.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "preprocess/import/indexed_mesh_source.h"
#include "src/core/status.h"
#include "store/material_record.h"

namespace nave::preprocess {

/// Bumped whenever CadPlugin's methods or the types they take change.
inline constexpr int kCadPluginVersion = 1;

/// Tessellation settings, in metres: the plugin converts every file to metres.
struct CadReadOptions {
    /// The store's grid step (`nave preprocess --precision`, metres for a CAD file); 0: the
    /// model's diagonal / 2^20, as the store's own default (preprocess_plan.h).
    double precision = 0;
};

/// How the linear deflection (the largest distance between a surface and its triangles) follows
/// the grid step: 256 steps, so that the default (diagonal / 2^20) gives diagonal / 4096, 2.4 cm
/// over a 100 m church and 0.24 mm over a 1 m part. Finer would only multiply triangles: the
/// store keeps positions to one step anyway.
inline constexpr double kDeflectionGridSteps = 256;
/// The angular deflection (the largest angle between the normals of neighbouring triangles on a
/// curved face), in radians: 20 degrees, so that a small column is still round (18 sides) when
/// the linear deflection alone would leave it square; shading normals come from the surface.
inline constexpr double kAngularDeflection = 0.35;

/// What the plugin saw of a file.
struct CadReadSummary {
    std::string format;     ///< "STEP", "IGES", "IFC4", "IFC2X3"
    std::string file_unit;  ///< the file's own length unit as it names it ("MM", "INCH", ...)
    double linear_deflection = 0;     ///< metres, as used
    double angular_deflection = 0;    ///< radians, as used
    uint64_t parts = 0;               ///< distinct shapes tessellated
    uint64_t instances = 0;           ///< placements of them (leaves of the assembly tree)
    uint64_t triangles = 0;           ///< emitted, over all instances
    uint64_t faces_without_mesh = 0;  ///< faces the tessellator could not mesh (skipped)
    /// IFC: triangles per entity type ("IfcWall"), and products left out (spaces, openings).
    std::vector<std::pair<std::string, uint64_t>> by_kind;
    uint64_t skipped_products = 0;
};

/// The Open CASCADE side.
class CadPlugin {
  public:
    virtual ~CadPlugin() = default;
    /// Reads `file` (STEP when its extension is .step/.stp, IGES for .iges/.igs) and calls `emit`
    /// for every placed part, once per material it has, with its triangles in metres in the
    /// model's frame (assembly transforms applied) and `material` indexing `materials`, which
    /// this call fills: one record per name (the part's layer, or its name) and colour. Parts are
    /// tessellated one at a time and their triangulation dropped after their last placement, so
    /// the triangles of the whole model are never held at once. Stops at the first error `emit`
    /// returns. Errors: DataLoss naming the file when the library refuses it (with what it said),
    /// fails on it, or finds no shape in it; ResourceExhausted when memory runs out.
    virtual StatusOr<CadReadSummary> ReadBrep(
        const std::filesystem::path& file, const CadReadOptions& options,
        const std::function<Status(IndexedMesh&&)>& emit,
        std::vector<store::MaterialRecord>& materials) const = 0;
};

/// Loads libnave_cad.so (once; later calls return the same plugin). Unsupported naming the
/// formats that are off when nave was built without Open CASCADE.
StatusOr<const CadPlugin*> LoadCadPlugin();

/// True when this build has the CAD plugin (Open CASCADE was found).
bool CadPluginBuilt();

}  // namespace nave::preprocess
