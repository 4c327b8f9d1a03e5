#include "preprocess/partition/brick_builder.h"

#include <bit>
#include <cmath>
#include <cstring>

namespace nave::preprocess {
BuiltBrick BuildBrickMesh(const std::vector<Triangle>& triangles, const store::GlobalGrid& grid) {
    BrickBuilder builder;
    return builder.Build(triangles, grid);
}

const BuiltBrick& BrickBuilder::Build(const std::vector<Triangle>& triangles,
                                      const store::GlobalGrid& grid) {
    BuiltBrick& out = out_;
    out.bounds = Bounds3f();
    out.collapsed_triangles = 0;
    bool normals = false, uvs = false;
    for (const Triangle& t : triangles) {
        normals |= t.has_normals;
        uvs |= t.has_uvs;
    }
    store::BrickMesh& mesh = out.mesh;
    mesh.positions.clear();
    mesh.normals.clear();
    mesh.uvs.clear();
    mesh.indices.clear();
    mesh.material_ids.clear();
    mesh.positions.reserve(triangles.size());
    if (normals) mesh.normals.reserve(triangles.size());
    if (uvs) mesh.uvs.reserve(triangles.size());
    mesh.indices.reserve(triangles.size() * 3);
    mesh.material_ids.reserve(triangles.size());
    // At most three vertices per triangle.
    vertices_.Reset(3 * triangles.size());
    for (const Triangle& t : triangles) {
        const Vec3i q[3] = {grid.Quantize(t.p[0]), grid.Quantize(t.p[1]), grid.Quantize(t.p[2])};
        // A triangle without normals in a brick with normals carries the normal of its snapped
        // corners: the encoder, which tests flatness on the snapped corners, then finds it flat
        // however small it is (from the unsnapped corners, millimetre faces of the billion-triangle
        // abbey came out up to degrees off and kept three stored normals each).
        Vec3f face_normal(0, 0, 1);
        if (normals) {
            const Vec3d n = store::GridNormal(q[0], q[1], q[2]);
            const double len = Length(n);
            if (len > 0 && std::isfinite(len)) face_normal = Vec3f(n / len);
        }
        uint32_t idx[3];
        for (int j = 0; j < 3; ++j) {
            VertexKey k{};
            k.q = q[j];
            Vec3f n = normals ? (t.has_normals ? t.n[j] : face_normal) : Vec3f();
            if (normals && t.has_normals) {
                // Bad input normals (zero, NaN, not unit) are replaced or renormalised, not passed
                // on.
                float len = Length(n);
                n = (len > 1e-12f && std::isfinite(len)) ? n / len : face_normal;
            }
            if (normals) {
                k.n[0] = std::bit_cast<uint32_t>(n.x);
                k.n[1] = std::bit_cast<uint32_t>(n.y);
                k.n[2] = std::bit_cast<uint32_t>(n.z);
            }
            std::array<float, 2> uv = t.has_uvs ? t.uv[j] : std::array<float, 2>{0.f, 0.f};
            if (uvs) {
                k.uv[0] = std::bit_cast<uint32_t>(uv[0]);
                k.uv[1] = std::bit_cast<uint32_t>(uv[1]);
            }
            bool inserted = false;
            idx[j] = vertices_.Insert(k, &inserted);
            if (inserted) {
                Vec3f p = grid.Dequantize(k.q);
                mesh.positions.push_back(p);
                out.bounds.Extend(p);
                if (normals) mesh.normals.push_back(n);
                if (uvs) mesh.uvs.push_back(uv);
            }
        }
        const Vec3i &a = vertices_.key(idx[0]).q, &b = vertices_.key(idx[1]).q,
                    &c = vertices_.key(idx[2]).q;
        if (a == b || b == c || a == c) {
            ++out.collapsed_triangles;
            continue;
        }
        mesh.indices.insert(mesh.indices.end(), {idx[0], idx[1], idx[2]});
        mesh.material_ids.push_back(t.material);
    }
    return out;
}

}  // namespace nave::preprocess
