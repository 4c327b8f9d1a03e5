#pragma once
// The geometry of one brick, decoded: what preprocess hands to the store writer and what the
// renderer gets back from the store. Plain data, no dependency on Draco or Embree.

#include <array>
#include <cstdint>
#include <vector>

#include "src/core/vecmath.h"

namespace nave::store {

/// An indexed triangle mesh. Invariants (checked by Validate in store_writer): indices.size() == 3
/// * T, material_ids.size() == T, every index < positions.size(), normals and uvs empty or one per
/// position.
struct BrickMesh {
    std::vector<Vec3f> positions;  ///< world coordinates (metres in nave's own models)
    /// Optional shading normals, unit length; zero at the corners of flat faces in decoded bricks
    /// (shade those with the geometric normal).
    std::vector<Vec3f> normals;
    std::vector<std::array<float, 2>> uvs;  ///< optional texture coordinates
    std::vector<uint32_t> indices;       ///< 3 per triangle, counter-clockwise seen from the front
    std::vector<uint32_t> material_ids;  ///< per triangle, an index into the store's material table

    size_t TriangleCount() const { return indices.size() / 3; }
    size_t VertexCount() const { return positions.size(); }
    bool HasNormals() const { return !normals.empty(); }
    bool HasUvs() const { return !uvs.empty(); }
    /// The corners of triangle `t`.
    std::array<Vec3f, 3> TrianglePositions(size_t t) const {
        return {positions[indices[3 * t]], positions[indices[3 * t + 1]],
                positions[indices[3 * t + 2]]};
    }
    /// The bytes a mesh of these counts holds with its vectors at their exact sizes (as decoding
    /// allocates them; a store directory's decoded_bytes).
    static uint64_t BytesFor(uint64_t vertex_count, uint64_t triangle_count, bool has_normals,
                             bool has_uvs) {
        return vertex_count * (sizeof(Vec3f) + (has_normals ? sizeof(Vec3f) : 0) +
                               (has_uvs ? sizeof(std::array<float, 2>) : 0)) +
               triangle_count * (3 * sizeof(uint32_t) + sizeof(uint32_t));
    }
    /// Bytes held by the vectors (for memory budgets): BytesFor(counts) when sized exactly.
    size_t MemoryBytes() const {
        return positions.capacity() * sizeof(Vec3f) + normals.capacity() * sizeof(Vec3f) +
               uvs.capacity() * sizeof(uvs[0]) + indices.capacity() * 4 +
               material_ids.capacity() * 4;
    }
};

}  // namespace nave::store
