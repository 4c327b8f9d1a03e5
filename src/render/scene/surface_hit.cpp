#include "src/render/scene/surface_hit.h"

namespace nave::render {

SurfaceHit MakeSurfaceHit(const RenderScene& scene, const ResidentBrick& brick, const BrickHit& hit,
                          const Vec3f& dir) {
    const ResidentMesh& m = brick.mesh();
    const uint32_t i0 = m.indices[3 * hit.triangle], i1 = m.indices[3 * hit.triangle + 1],
                   i2 = m.indices[3 * hit.triangle + 2];
    const float w0 = 1 - hit.u - hit.v;
    SurfaceHit h;
    // The point from the barycentrics (not o + t d): exact to the triangle's plane whatever t's
    // magnitude.
    h.p = m.positions[i0] * w0 + m.positions[i1] * hit.u + m.positions[i2] * hit.v;
    h.ng = Normalize(Cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]));
    h.ns = h.ng;
    // Coarse levels shade with their facets' normals: the full mesh's vertex normals, kept on a
    // level's vertices, bend far from its larger facets and would send light under them.
    if (m.HasNormals() && brick.lod().level == 0) {
        Vec3f n = m.normals[i0] * w0 + m.normals[i1] * hit.u + m.normals[i2] * hit.v;
        float len = Length(n);
        if (len > 0) h.ns = n / len;
        if (Dot(h.ns, h.ng) < 0) h.ns = -h.ns;  // winding decides the front; normals only bend it
    }
    if (m.HasUvs()) {  // [texture]
        for (int k = 0; k < 2; ++k)
            h.uv[k] = m.uvs[i0][k] * w0 + m.uvs[i1][k] * hit.u + m.uvs[i2][k] * hit.v;
        h.has_uv = true;
    }
    uint32_t mat = m.material_ids[hit.triangle];
    static const SurfaceMaterial kBlack = [] {
        SurfaceMaterial s;
        s.black = true;
        return s;
    }();
    h.material = mat < scene.materials.size() ? &scene.materials[mat] : &kBlack;
    h.lod = brick.lod();
    if (h.has_uv && h.material->textures) {
        // The texture filter footprint as the camera would see this point (pbrt-v4's approximation
        // for every vertex of a path, Camera::Approximate_dp_dxy): a cone of one pixel's spread
        // from the camera, widened by the incidence and carried to texture space by the triangle's
        // texture-to-world scale (Ray Tracing Gems ch. 20). Secondary vertices see a sharper
        // texture than their real footprint: conservative.
        const auto& t0 = m.uvs[i0];
        const auto& t1 = m.uvs[i1];
        const auto& t2 = m.uvs[i2];
        const float uv_area =
            0.5f * std::abs((t1[0] - t0[0]) * (t2[1] - t0[1]) - (t2[0] - t0[0]) * (t1[1] - t0[1]));
        const float world_area = 0.5f * Length(Cross(m.positions[i1] - m.positions[i0],
                                                     m.positions[i2] - m.positions[i0]));
        const float cone_width =
            Length(h.p - scene.camera->position()) * scene.camera->PixelSpreadAngle();
        h.footprint = imaging::RayConeFootprint(cone_width, Dot(dir, h.ng), uv_area, world_area);
    }
    return h;
}

}  // namespace nave::render
