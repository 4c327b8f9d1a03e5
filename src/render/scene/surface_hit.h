#pragma once
// A ray's hit on a brick's mesh as the shading code sees it (point, normals, texture coordinates
// and footprint, material), and leaving that surface again.

#include <algorithm>
#include <array>
#include <cmath>

#include "src/core/vecmath.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/scene/materials/bxdf.h"
#include "src/render/scene/scene.h"

namespace nave::render {

/// The geometry of a hit, from the brick's mesh.
struct SurfaceHit {
    Vec3f p, ng, ns;
    std::array<float, 2> uv{};  ///< [texture] interpolated texture coordinates, when has_uv
    bool has_uv = false;
    /// Texture filter footprint at the hit (with uv on a textured material).
    TextureFootprint footprint;
    /// Points into the scene's materials, or to a static black one for an unmapped id.
    const SurfaceMaterial* material = nullptr;
    /// The level of detail of the mesh hit (level 0: full detail).
    LevelOfDetail lod;
};

/// The geometry of `hit` on the mesh of `brick`, its material from `scene` (a material id the scene
/// does not map reads as black); `dir` is the ray's direction (for the texture footprint).
/// Thread-safe.
SurfaceHit MakeSurfaceHit(const RenderScene& scene, const ResidentBrick& brick, const BrickHit& hit,
                          const Vec3f& dir);

/// Moves p off the surface to the side of `w`, so that the spawned ray does not hit the surface it
/// leaves. The offset grows with |p| because float spacing does (2^-23 relative).
inline Vec3f OffsetOrigin(const Vec3f& p, const Vec3f& ng, const Vec3f& w) {
    float scale = 1e-5f * (1.f + std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}));
    return p + ng * (Dot(ng, w) >= 0 ? scale : -scale);
}

/// A straight pass through thin glass: the path continues in the same direction, and this is not a
/// scattering event (depth, MIS state unchanged), as for shadow rays.
inline bool IsPassThrough(const SurfaceMaterial& m, const BsdfSample& bs) {
    return m.thin_glass() != nullptr && bs.IsTransmission();
}

}  // namespace nave::render
