#pragma once
// Encoding and decoding of one brick's payload (internal to nave_store). The mesh section is a
// 16-byte prefix (the brick's integer position base) followed by a Draco bitstream; the side
// section is LZ4. Byte layouts: docs/store-format.md. No Draco or LZ4 type leaves brick_codec.cpp.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "src/core/status.h"
#include "store/brick_mesh.h"
#include "store/grid.h"
#include "store/store_writer.h"

namespace nave::store::codec {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// Bytes of the mesh section's prefix (int32 base x, y, z; uint32 flags).
inline constexpr size_t kMeshPrefixBytes = 16;
/// Mesh section flag (prefix word 3, format 2.0, no longer written): the material attribute holds
/// material * 2 + 1 on flat faces (shaded with their geometric normal; their decoded normals are
/// zero) and material * 2 on smooth ones. Unset: the attribute is the material.
inline constexpr uint32_t kMeshFlagFlatFaces = 1u;
/// Mesh section flag (format 3.0): the material attribute holds material * 16 + smoothing group
/// * 4 + shading (face_shading.h). Unset (and kMeshFlagFlatFaces unset): the attribute is the
/// material, and the brick has no normals or every face keeps its own.
inline constexpr uint32_t kMeshFlagShading = 2u;
/// Mesh section prefix flags, bits 8-12 (format 3.2): the grid shift s. Positions are stored in
/// units of 2^s grid steps (relative to the base, itself in grid steps): a coarse level snaps to a
/// coarser grid than its brick, and its positions take fewer bits. 3.1 readers refuse the section
/// (unknown flag bits) rather than read it at the wrong scale.
inline constexpr uint32_t kMeshGridShiftBit = 8;
inline constexpr uint32_t kMeshGridShiftMask = 0x1fu << kMeshGridShiftBit;
/// Largest grid shift a section may carry (positions on a grid 65 536 steps apart).
inline constexpr uint32_t kMaxMeshGridShift = 16;
/// Largest material id a brick can store (shading and smoothing group take four bits of the int32
/// value).
inline constexpr uint32_t kMaxMaterialId = (1u << 27) - 1;
/// Largest span of a brick's positions along one axis, in grid steps. Keeps Draco's integer
/// prediction (a + b - c, in int32) far from overflow.
inline constexpr int64_t kMaxBrickSpanSteps = int64_t(1) << 29;

/// The result of encoding a mesh: the section bytes and what the directory needs to know.
struct EncodedMesh {
    std::string bytes;
    Bounds3f geometry_bounds;  ///< box of the decoded (grid-snapped) positions
    uint64_t triangle_count =
        0;  ///< stored triangles (input minus those that collapse on the grid)
    uint64_t vertex_count =
        0;  ///< vertices after decoding (Draco splits vertices at attribute seams)
    uint64_t decoded_bytes = 0;
    uint64_t dropped_triangle_count = 0;
    uint32_t max_material_id = 0;
    bool has_normals = false;
    bool has_uvs = false;
    /// OccupancyGrid::Encode of the triangles as they decode (options.occupancy, at the grid's
    /// own step only; empty otherwise, and for a section of no triangles).
    std::string occupancy;
    /// The section decoded, when options.verify decoded it to check it (else empty): what the
    /// store's reader will return for it.
    std::optional<BrickMesh> decoded;
};

/// Snaps, encodes, then decodes the result once to check it and to learn the decoded counts.
/// `complete_within` is the box inside which the mesh holds every face around each vertex (a
/// brick's cell: bricks hold every triangle that overlaps it); only there may normals be derived
/// (face_shading.h). With `grid_shift` s > 0 positions snap to every 2^s-th point of `grid`
/// (kMaxMeshGridShift at most). Thread-safe.
StatusOr<EncodedMesh> EncodeMeshSection(
    const BrickMesh& mesh, const GlobalGrid& grid, const EncodeOptions& options,
    const Bounds3f& complete_within = Bounds3f(Vec3f(-kInfinity, -kInfinity, -kInfinity),
                                               Vec3f(kInfinity, kInfinity, kInfinity)),
    uint32_t grid_shift = 0);

/// Decodes a mesh section. `material_count` bounds the material ids; `what` prefixes every error
/// ("abbey.nave brick 12 @0x1a2b"). Thread-safe.
StatusOr<BrickMesh> DecodeMeshSection(std::string_view bytes, const GlobalGrid& grid,
                                      uint64_t material_count, const std::string& what);

/// LZ4-compresses a side section: uint64 raw size, then one LZ4 block.
std::string CompressSideSection(std::string_view raw);
/// Inverse of CompressSideSection; errors (DataLoss) are prefixed by `what`.
StatusOr<std::string> DecompressSideSection(std::string_view bytes, const std::string& what);

}  // namespace nave::store::codec
