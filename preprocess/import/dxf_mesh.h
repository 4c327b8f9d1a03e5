#pragma once
// DXF MESH entities (AutoCAD's subdivision meshes, AcDbSubDMesh, since AutoCAD 2010): Assimp 5.2's
// DXF reader takes 3DFACE and polyface meshes but not these, and no other library in Debian reads
// DXF, so nave reads them itself: each entity's layer, its level-0 vertices and its faces (the
// control mesh; the subdivision level an editor would smooth it to is not applied). Read beside
// Assimp's result in the same child process (assimp_scene.cpp).

#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/import/indexed_mesh_source.h"
#include "src/core/status.h"

namespace nave::preprocess {

/// One MESH entity: its layer and its faces triangulated (positions as in the file).
struct DxfMesh {
    std::string layer = "0";  ///< DXF's default layer when the entity names none
    IndexedMesh mesh;
};

/// The MESH entities of the ASCII DXF file `path`, in file order; none for a file without them.
/// Errors: IoError when it cannot be read; DataLoss naming the file and the line where a MESH
/// entity's counts or indices do not hold (a vertex count beyond the vertices given, a face
/// naming a vertex that does not exist).
StatusOr<std::vector<DxfMesh>> ReadDxfMeshEntities(const std::filesystem::path& path);

}  // namespace nave::preprocess
