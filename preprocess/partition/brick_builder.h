#pragma once
// Turns a brick's triangles into an indexed BrickMesh: vertices shared when their grid position,
// normal and texture coordinates agree (positions are snapped to the store's global grid here, as
// the store will). A brick has normals if any of its triangles has; flat triangles then carry their
// face normal (likewise texture coordinates, (0, 0) where absent).

#include <vector>

#include "preprocess/triangle_source.h"
#include "src/core/key_table.h"
#include "store/brick_mesh.h"
#include "store/grid.h"

namespace nave::preprocess {

struct BuiltBrick {
    store::BrickMesh mesh;
    Bounds3f bounds;                   ///< of the snapped positions
    uint64_t collapsed_triangles = 0;  ///< dropped: two corners on one grid point
};

/// Builds bricks one after the other, reusing its buffers (large fresh allocations cost page faults
/// on every brick). Not thread-safe: one per encoding thread.
class BrickBuilder {
  public:
    /// The returned brick stays valid until the next call.
    const BuiltBrick& Build(const std::vector<Triangle>& triangles, const store::GlobalGrid& grid);

  private:
    struct VertexKey {
        Vec3i q;
        uint32_t n[3];
        uint32_t uv[2];
    };
    BuiltBrick out_;
    KeyTable<VertexKey> vertices_;
};

/// One-off convenience over BrickBuilder.
BuiltBrick BuildBrickMesh(const std::vector<Triangle>& triangles, const store::GlobalGrid& grid);

/// Working memory of BuildBrickMesh + EncodeBrick per triangle, in bytes: the Triangle list, the
/// mesh (about one vertex per triangle), the vertex hash table and the encoder's buffers (measured
/// on the abbey and on scans, with a margin; see docs/preprocess.md "Memory").
inline constexpr uint64_t kEncodeBytesPerTriangle = 600;

}  // namespace nave::preprocess
