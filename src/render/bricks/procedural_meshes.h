#pragma once
// Small procedural meshes for tests, benchmarks and test scenes (configs/): spheres, planes, boxes.

#include <cstdint>

#include "src/core/vecmath.h"
#include "store/brick_mesh.h"

namespace nave::render {

/// A UV sphere of `rings` x `segments` quads (split into triangles), outward-facing (CCW seen from
/// outside), with unit shading normals. `inward` flips the winding and normals (a closed room seen
/// from inside).
void AppendSphere(store::BrickMesh* mesh, Vec3f center, float radius, int rings, int segments,
                  uint32_t material, bool inward = false);
/// A rectangle centred on `center`, spanned by `half_u` and `half_v`, facing `Cross(half_u,
/// half_v)`, cut into n x n quads.
void AppendQuad(store::BrickMesh* mesh, Vec3f center, Vec3f half_u, Vec3f half_v, int n,
                uint32_t material);
/// An axis-aligned box, outward-facing.
void AppendBox(store::BrickMesh* mesh, Bounds3f box, uint32_t material);

}  // namespace nave::render
