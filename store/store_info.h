#pragma once
// What a store says about itself: header fields and the brick directory. See docs/store-format.md.

#include <cstdint>
#include <string>
#include <vector>

#include "src/core/vecmath.h"
#include "store/grid.h"

namespace nave::store {

/// Current format version. Readers refuse another major version; a newer minor version only adds
/// fields. The version this nave writes. 3.4: each brick's occupancy grid (where its full mesh has
/// triangles; the occupancy table; older readers ignore it and stores without it have none). 3.3:
/// a medium's density grid cut along the bricks (the
/// medium table; older readers ignore it and stores without it have no medium), and bricks without
/// triangles that hold only a piece of it. 3.2: a level's mesh section may snap to a coarser grid.
/// 3.1: levels of detail, coarser meshes of each brick (the
/// levels table; older readers ignore it and stores without it have no levels). 3.0: each face's
/// shading (stored, flat or derived normals) in the mesh section, so that smooth surfaces too may
/// store no normals. 2.0: flat faces marked in the mesh section (no normals, shared corners). 1.1:
/// material alpha_cutoff.
inline constexpr uint16_t kFormatMajor = 3;
inline constexpr uint16_t kFormatMinor = 4;
/// The oldest major version this nave still reads (1.x stores decode as before).
inline constexpr uint16_t kOldestReadableMajor = 1;

/// Header fields that the writer's caller provides: how the store was made and from what.
struct StoreProvenance {
    std::vector<std::string> source_files;  ///< inputs, as given on the command line
    std::string tool_version;               ///< "nave 0.1.0"
    std::string options;  ///< the creation options, as text ("brick-triangles=1000000 ...")
};

/// One section of the file, where it is and its checksum: a table the header points to (provenance,
/// directory, tree, materials) or a section of a brick (the Draco mesh, a side section).
struct SectionInfo {
    uint64_t offset = 0;    ///< byte offset from the start of the file
    uint64_t length = 0;    ///< bytes on disk
    uint64_t checksum = 0;  ///< XXH64 of those bytes
};

/// A coarser version of a brick (docs/store-format.md, "Levels"). Level 0 is the brick itself
/// (BrickInfo's own fields); BrickInfo::levels[k - 1] is level k.
struct LevelInfo {
    float error = 0;  ///< estimated largest distance from the full surface, model units
    uint64_t triangle_count = 0;
    uint64_t vertex_count = 0;
    uint64_t decoded_bytes = 0;  ///< as BrickInfo::decoded_bytes
    bool has_normals = false;
    bool has_uvs = false;
    SectionInfo mesh;  ///< position base + Draco mesh, as the brick's own mesh section
};

/// The brick's piece of the store's medium density grid (format 3.3): the grid's active voxels
/// whose cells overlap the brick's cell, in OpenVDB's serialization (volumes::GridPiece::bytes).
/// grid.length 0: none.
struct BrickMediumInfo {
    SectionInfo grid;
    uint64_t active_voxels = 0;
    float max_density = 0;       ///< the largest density in the piece: its majorant
    uint64_t decoded_bytes = 0;  ///< memory once read (GridPiece::memory_bytes), for budgets
};

/// A brick as the directory describes it. Reading the directory never touches brick payloads.
struct BrickInfo {
    uint32_t id = 0;
    Bounds3f cell;  ///< the brick's cell in the brick tree (disjoint from every other cell)
    Bounds3f geometry_bounds;  ///< box of the brick's triangles (may exceed `cell` for triangles
                               ///< that cross it)
    uint64_t triangle_count = 0;
    uint64_t vertex_count = 0;
    uint64_t decoded_bytes = 0;  ///< BrickMesh::MemoryBytes() once decoded (for memory budgets)
    bool has_normals = false;    ///< the decoded mesh has shading normals
    bool has_uvs = false;        ///< the decoded mesh has texture coordinates
    SectionInfo mesh;            ///< position base + Draco-encoded mesh (docs/store-format.md)
    SectionInfo side;  ///< LZ4-compressed side section (see docs/store-format.md); length 0 if none
    /// Coarser versions of the brick, coarsest last, each with a larger error (the store's levels
    /// table, format 3.1); empty for stores without levels.
    std::vector<LevelInfo> levels;
    /// The brick's piece of the medium (the store's medium table, format 3.3). A brick may hold
    /// a piece and no triangles: it stands for a cell of the tree where the medium is and no
    /// surface is.
    BrickMediumInfo medium;
    /// Where the brick's full mesh has triangles (store/occupancy_grid.h: OccupancyGrid::Encode),
    /// from the store's occupancy table (format 3.4); length 0: none (no triangles, or an older
    /// store).
    SectionInfo occupancy;
    /// What a load of the brick reads: its mesh, side and medium sections (not its levels', nor
    /// its occupancy grid, which a renderer reads once when it opens the store).
    uint64_t BytesOnDisk() const { return mesh.length + side.length + medium.grid.length; }
};

struct StoreHeader {
    uint16_t major = kFormatMajor;
    uint16_t minor = kFormatMinor;
    GlobalGrid grid;
    Bounds3f bounds;  ///< box of all geometry
    uint64_t triangle_count =
        0;  ///< sum over bricks (triangles crossing cells counted once per brick)
    uint64_t source_triangle_count =
        0;  ///< triangles in the input before duplication across bricks
    StoreProvenance provenance;
    /// The name of the medium's density grid the bricks hold pieces of (format 3.3: the medium
    /// table); "" when the store has no medium.
    std::string medium_grid;
    /// XXH64 of the header's bytes as stored (which hold the checksums of every table): the
    /// store's identity, for render checkpoints.
    uint64_t header_checksum = 0;
};

}  // namespace nave::store
