#pragma once
// A brick's mesh as the renderer holds it while the brick is resident: the arrays of a
// store::BrickMesh laid out in one PageRegion of their exact size. Evicting the brick gives all its
// pages back to the system, so paging thousands of bricks of many sizes in and out leaves no holes
// in malloc's heap (docs/pager.md, "Memory").

#include <array>
#include <cstdint>
#include <span>

#include "src/core/page_region.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "store/brick_mesh.h"

namespace nave::render {

/// The sizes of a mesh's arrays (store::BrickMesh's invariants: normals and uvs empty or one per
/// vertex).
struct MeshCounts {
    uint64_t vertices = 0;
    uint64_t triangles = 0;
    bool normals = false;
    bool uvs = false;
};

/// Read-only after it is filled. The arrays have store::BrickMesh's names and meaning; the
/// positions hold one spare vertex after the last, for Embree's 16-byte vertex loads.
class ResidentMesh {
  public:
    /// The arrays of a freshly allocated mesh, for whoever fills it.
    struct Writable {
        std::span<Vec3f> positions;
        std::span<Vec3f> normals;
        std::span<std::array<float, 2>> uvs;
        std::span<uint32_t> indices;
        std::span<uint32_t> material_ids;
    };

    ResidentMesh() = default;

    /// A zero-filled mesh of `counts`; `writable` receives its arrays. Errors: no memory.
    static StatusOr<ResidentMesh> Allocate(const MeshCounts& counts, Writable* writable);
    /// A copy of `mesh` (whose invariants hold).
    static StatusOr<ResidentMesh> CopyOf(const store::BrickMesh& mesh);
    /// The bytes a mesh of `counts` holds (what MemoryBytes() returns once it is allocated).
    static uint64_t MemoryBytesFor(const MeshCounts& counts);

    uint64_t MemoryBytes() const { return region_.size(); }
    size_t TriangleCount() const { return indices.size() / 3; }
    size_t VertexCount() const { return positions.size(); }
    bool HasNormals() const { return !normals.empty(); }
    bool HasUvs() const { return !uvs.empty(); }
    /// The corners of triangle `t`.
    std::array<Vec3f, 3> TrianglePositions(size_t t) const {
        return {positions[indices[3 * t]], positions[indices[3 * t + 1]],
                positions[indices[3 * t + 2]]};
    }

    std::span<const Vec3f> positions;
    std::span<const Vec3f>
        normals;  ///< zero at the corners of flat faces (shade those with the geometric normal)
    std::span<const std::array<float, 2>> uvs;
    std::span<const uint32_t> indices;  ///< 3 per triangle, counter-clockwise seen from the front
    std::span<const uint32_t> material_ids;

  private:
    PageRegion region_;
};

}  // namespace nave::render
