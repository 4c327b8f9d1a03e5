#include "src/render/bricks/procedural_meshes.h"

#include <cmath>

#include "src/core/sampling.h"

namespace nave::render {

void AppendSphere(store::BrickMesh* mesh, Vec3f center, float radius, int rings, int segments,
                  uint32_t material, bool inward) {
    const uint32_t base = uint32_t(mesh->positions.size());
    const bool with_normals = mesh->positions.empty() || mesh->HasNormals();
    for (int i = 0; i <= rings; ++i) {
        // The poles and the seam exactly where their neighbours are (sin(pi) and sin(2 pi) are not
        // 0 in float): a crack of 1e-7 radii there lets rays through a closed sphere.
        const float theta = kPi * float(i) / float(rings);
        const float sin_theta = (i == 0 || i == rings) ? 0.f : std::sin(theta);
        const float cos_theta = i == 0 ? 1.f : i == rings ? -1.f : std::cos(theta);
        for (int j = 0; j <= segments; ++j) {
            const float phi = 2 * kPi * float(j % segments) / float(segments);
            Vec3f n(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
            mesh->positions.push_back(center + n * radius);
            if (with_normals) mesh->normals.push_back(inward ? -n : n);
        }
    }
    auto vid = [&](int i, int j) { return base + uint32_t(i * (segments + 1) + j); };
    auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
        if (inward) std::swap(b, c);
        mesh->indices.insert(mesh->indices.end(), {a, b, c});
        mesh->material_ids.push_back(material);
    };
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            // Outward CCW: going down in theta (i -> i+1) and around in phi (j -> j+1).
            if (i != 0) tri(vid(i, j), vid(i + 1, j), vid(i, j + 1));
            if (i != rings - 1) tri(vid(i, j + 1), vid(i + 1, j), vid(i + 1, j + 1));
        }
    }
}

void AppendQuad(store::BrickMesh* mesh, Vec3f center, Vec3f half_u, Vec3f half_v, int n,
                uint32_t material) {
    const uint32_t base = uint32_t(mesh->positions.size());
    const bool with_normals = mesh->positions.empty() || mesh->HasNormals();
    Vec3f normal = Normalize(Cross(half_u, half_v));
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
            float a = 2.f * float(i) / float(n) - 1.f, b = 2.f * float(j) / float(n) - 1.f;
            mesh->positions.push_back(center + half_u * a + half_v * b);
            if (with_normals) mesh->normals.push_back(normal);
        }
    }
    auto vid = [&](int i, int j) { return base + uint32_t(i * (n + 1) + j); };
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            mesh->indices.insert(mesh->indices.end(),
                                 {vid(i, j), vid(i + 1, j), vid(i + 1, j + 1)});
            mesh->indices.insert(mesh->indices.end(),
                                 {vid(i, j), vid(i + 1, j + 1), vid(i, j + 1)});
            mesh->material_ids.push_back(material);
            mesh->material_ids.push_back(material);
        }
    }
}

void AppendBox(store::BrickMesh* mesh, Bounds3f box, uint32_t material) {
    Vec3f c = box.Center(), h = box.Diagonal() * 0.5f;
    Vec3f ex(h.x, 0, 0), ey(0, h.y, 0), ez(0, 0, h.z);
    AppendQuad(mesh, c + ez, ex, ey, 1, material);
    AppendQuad(mesh, c - ez, ey, ex, 1, material);
    AppendQuad(mesh, c + ex, ey, ez, 1, material);
    AppendQuad(mesh, c - ex, ez, ey, 1, material);
    AppendQuad(mesh, c + ey, ez, ex, 1, material);
    AppendQuad(mesh, c - ey, ex, ez, 1, material);
}

}  // namespace nave::render
