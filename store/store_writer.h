#pragma once
// Writing a store. Encoding a brick (EncodeBrick) is thread-safe and independent of the writer, so
// that preprocess encodes on many threads and appends the results as they finish. The file is
// written under a temporary name; Finish() writes the tables last, then fsyncs and renames: an
// interrupted writer never leaves a file that opens as a valid store.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "store/brick_levels.h"
#include "store/brick_mesh.h"
#include "store/brick_tree.h"
#include "store/material_record.h"
#include "store/store_info.h"

namespace nave::store {

/// Encoder settings. Defaults and why: docs/store-format.md.
struct EncodeOptions {
    int draco_speed = 6;   ///< Draco encoder/decoder speed 0 (smallest) .. 10 (fastest)
    int normal_bits = 10;  ///< octahedral quantization of normals
    int uv_bits = 14;      ///< quantization of texture coordinates
    /// Draco's sequential connectivity coding instead of edgebreaker: larger, but decodes faster
    /// on meshes of many small parts with split vertices (bench_brick_load).
    bool sequential = false;
    /// Largest angle, in degrees, between a derived normal (recomputed from the positions when a
    /// brick is decoded) and the given one for a face to store no normals (face_shading.h); 0
    /// stores the normals of every face that is not flat. Why 3: docs/store-format.md, "Shading".
    double derived_normal_error_deg = 3.0;
    /// Decode every brick once after encoding and compare its counts, materials and bounds with
    /// what was encoded. Off, encoding is about a third faster and the counts come from Draco's
    /// encoder (docs/preprocess.md, "Verification").
    bool verify = true;
    /// Coarser levels of each brick to make and store beside it (brick_levels.h); no errors, the
    /// default here, makes none. `nave preprocess` makes LevelOptions' defaults.
    LevelOptions levels = {.relative_errors = {}};
    /// Store each brick's occupancy grid (format 3.4; store/occupancy_grid.h): where its full mesh
    /// has triangles, so that a renderer passes over the bricks a ray crosses only through air
    /// without loading them. 32 KiB a brick before LZ4.
    bool occupancy = true;
};

/// A level of a brick ready to be appended (format 3.1): its mesh section and table fields.
struct EncodedLevel {
    std::string mesh_bytes;  ///< mesh section, as EncodedBrick::mesh_bytes
    float error = 0;         ///< BrickLevel::error: estimated distance from the full surface
    uint64_t triangle_count = 0;
    uint64_t vertex_count = 0;
    uint64_t decoded_bytes = 0;
    bool has_normals = false;
    bool has_uvs = false;
    uint32_t max_material_id = 0;
};

/// A brick ready to be appended: encoded bytes and the directory fields known before writing.
struct EncodedBrick {
    std::string mesh_bytes;  ///< mesh section: 16-byte position base, then the Draco bitstream
    std::string side_bytes;  ///< LZ4 side section (empty in format 1.0; see docs/store-format.md)
    /// Occupancy section (format 3.4: OccupancyGrid::Encode); empty: none.
    std::string occupancy_bytes;
    Bounds3f cell;
    Bounds3f geometry_bounds;     ///< box of the grid-snapped positions, exactly as they decode
    uint64_t triangle_count = 0;  ///< stored triangles (input minus dropped_triangle_count)
    uint64_t vertex_count =
        0;  ///< vertices once decoded (Draco splits vertices at material borders)
    uint64_t decoded_bytes = 0;
    bool has_normals = false;
    bool has_uvs = false;
    uint32_t max_material_id =
        0;  ///< largest material id used (Finish checks it against the table)
    uint64_t dropped_triangle_count =
        0;  ///< input triangles whose corners collapsed onto <= 2 grid points
    /// Coarser levels, finest first, each with a larger error (EncodeOptions::levels).
    std::vector<EncodedLevel> levels;
    double simplify_seconds = 0;  ///< time spent making the levels (statistics; not stored)
};

/// A brick's piece of the store's medium, ready to be appended (format 3.3): BrickMediumInfo's
/// fields and the section's bytes.
struct EncodedMedium {
    std::vector<std::byte> grid_bytes;  ///< OpenVDB's serialization (volumes::GridPiece::bytes)
    uint64_t active_voxels = 0;         ///< at least 1
    float max_density = 0;              ///< the majorant: finite, >= 0
    uint64_t decoded_bytes = 0;         ///< memory once read (volumes::GridPiece::memory_bytes)
};

/// A brick without triangles for `cell`, one that holds only a piece of the medium: its mesh
/// section is the 16-byte prefix alone (base 0, no flags, no Draco bitstream), as a brick whose
/// triangles all collapsed on the grid has, which every reader decodes to an empty mesh.
EncodedBrick EmptyBrick(const Bounds3f& cell);

/// Checks BrickMesh invariants; errors say which index or count is wrong.
Status ValidateBrickMesh(const BrickMesh& mesh, size_t material_count);

/// Snaps positions to `grid` and encodes, then decodes the result once to check it (when
/// options.verify); makes and encodes the levels options.levels asks for the same way (a level
/// whose triangles all collapse on the grid is not kept, nor any coarser one). Thread-safe.
/// Triangles that collapse on the grid (two corners on one grid point: zero area) are dropped and
/// counted. Fails (InvalidArgument) on a mesh that breaks the invariants, a position outside the
/// grid's int32 range or a brick spanning more than 2^29 grid steps.
StatusOr<EncodedBrick> EncodeBrick(const BrickMesh& mesh, const Bounds3f& cell,
                                   const GlobalGrid& grid, const EncodeOptions& options);

class StoreWriter {
  public:
    /// Starts writing `path` (through a temporary file beside it).
    static StatusOr<std::unique_ptr<StoreWriter>> Create(const std::filesystem::path& path,
                                                         const GlobalGrid& grid,
                                                         StoreProvenance provenance);
    ~StoreWriter();  // abandons the temporary file unless Finish() succeeded

    /// Appends a brick (its mesh section, then its levels', then its side section) and returns its
    /// id (ids count from 0 in append order). Not thread-safe.
    StatusOr<uint32_t> Append(const EncodedBrick& brick);
    /// Names the medium's density grid (format 3.3) whose pieces AppendMedium adds: the store then
    /// has a medium table (StoreHeader::medium_grid), even if no piece is appended. Call it once,
    /// before AppendMedium; InvalidArgument for an empty name or a second call.
    Status SetMediumGrid(const std::string& grid);
    /// Appends the piece of the medium of brick `id` (appended before; at most one piece a brick):
    /// its section goes after the payloads so far. InvalidArgument for an unknown brick, a second
    /// piece, no SetMediumGrid, no bytes or voxels, or a majorant that is not finite and >= 0. Not
    /// thread-safe.
    Status AppendMedium(uint32_t id, const EncodedMedium& medium);
    /// Writes the materials, the brick tree (whose leaves name appended brick ids), the directory,
    /// the levels table, the medium table and the header, then commits the file.
    /// `source_triangle_count` is the input's count before duplication.
    Status Finish(const std::vector<MaterialRecord>& materials, const BrickTree& tree,
                  uint64_t source_triangle_count);

    uint64_t bytes_written() const;

  private:
    struct Impl;
    explicit StoreWriter(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace nave::store
