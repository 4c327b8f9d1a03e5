#pragma once
// The one interface every model producer implements: importers (OBJ, PLY, STL, glTF, Assimp), the
// procedural abbey and the merge of several inputs. The partitioner pulls batches of triangles from
// it in one forward pass, so a producer never has to hold the whole model.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "preprocess/import_warnings.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "store/material_record.h"

namespace nave::preprocess {

/// One triangle as a source produces it. Corners are counter-clockwise seen from the front
/// (outside).
struct Triangle {
    std::array<Vec3f, 3> p;                    ///< positions, in the model's units
    std::array<Vec3f, 3> n{};                  ///< shading normals (valid when has_normals)
    std::array<std::array<float, 2>, 3> uv{};  ///< texture coordinates (valid when has_uvs)
    uint32_t material = 0;                     ///< index into the source's materials()
    bool has_normals = false;
    bool has_uvs = false;
};

/// A stream of triangles. Not thread-safe: one consumer pulls batches in order.
class TriangleSource {
  public:
    virtual ~TriangleSource() = default;

    /// Clears `batch` and fills it with up to `max_triangles` triangles. Returns false (and an
    /// empty batch) once the stream is exhausted. Errors name the file and the line or byte offset.
    virtual StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) = 0;

    /// The material table. Triangle::material indexes it. It may grow while streaming (an OBJ
    /// `usemtl` of a name no MTL defined adds a default material); complete once Next() returned
    /// false.
    virtual const std::vector<store::MaterialRecord>& materials() const = 0;

    /// What the source reads ("bunny.ply", "abbey:detail=1"), for messages and provenance.
    virtual std::string name() const = 0;

    /// The model's length unit as far as the source knows it: "m" (glTF, the abbey) or "unknown"
    /// (OBJ, PLY, STL carry no unit). Positions are never converted.
    virtual std::string units() const { return "unknown"; }

    /// What the file says of itself that the store keeps (in its options text, as `content=`;
    /// `nave inspect` shows it): the format, its length unit and, for IFC, triangles per entity
    /// type: "IFC4;unit=0.001m;IfcWall=56,IfcWindow=60". No spaces. Empty when there is nothing
    /// to say (OBJ, PLY...).
    virtual std::string content() const { return {}; }

    /// Progress in source-specific units (bytes read for files, parts generated for the abbey) and
    /// the total (0 if unknown), for progress bars.
    virtual uint64_t progress_done() const = 0;
    virtual uint64_t progress_total() const = 0;
    /// What progress counts, for the bar: "bytes" (streamed files), "triangles" (models read
    /// whole, or tessellated), "parts" (the abbey).
    virtual std::string progress_unit() const { return "bytes"; }

    /// Memory the source itself holds (OBJ and PLY vertex arrays grow with the input; glTF and
    /// Assimp hold the whole model), in bytes, for the memory budget and the summary.
    virtual uint64_t memory_bytes() const { return 0; }
    /// Writes the image files a generated model's materials name (relative to `dir`), for the
    /// texture conversion to pick up; importers name files that exist already and write nothing.
    virtual Status WriteGeneratedTextures(const std::filesystem::path& dir) const {
        (void)dir;
        return Status::Ok();
    }

    /// Problems the source skipped over (degenerate faces, missing textures...), counted.
    virtual const ImportWarnings& warnings() const = 0;
};

/// Reads every triangle of `source` into memory (for tests and small models).
StatusOr<std::vector<Triangle>> ReadAll(TriangleSource& source);

}  // namespace nave::preprocess
