#include "preprocess/partition/brick_builder.h"

#include <bit>
#include <cmath>
#include <cstring>

namespace nave::preprocess {
namespace {

template <typename Key>
bool SameKey(const Key& a, const Key& b) {
    return std::memcmp(&a, &b, sizeof(Key)) == 0;
}

template <typename Key>
uint64_t HashKey(const Key& k) {
    uint32_t words[sizeof(Key) / 4];
    std::memcpy(words, &k, sizeof(Key));
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t v : words) {
        h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
    }
    return h ^ (h >> 29);
}

}  // namespace

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
    keys_.clear();
    keys_.reserve(triangles.size());
    mesh.positions.reserve(triangles.size());
    if (normals) mesh.normals.reserve(triangles.size());
    if (uvs) mesh.uvs.reserve(triangles.size());
    mesh.indices.reserve(triangles.size() * 3);
    mesh.material_ids.reserve(triangles.size());
    // Open addressing with linear probing; slots hold vertex index + 1 (0: empty). At most three
    // vertices per triangle, so the table is at most half full.
    size_t cap = 16;
    while (cap < 6 * triangles.size() + 32) cap <<= 1;
    slots_.assign(cap, 0);
    const size_t mask = cap - 1;
    auto find = [&](const VertexKey& key, bool* inserted) -> uint32_t {
        size_t i = HashKey(key) & mask;
        while (true) {
            uint32_t s = slots_[i];
            if (s == 0) {
                uint32_t next = uint32_t(keys_.size());
                slots_[i] = next + 1;
                keys_.push_back(key);
                *inserted = true;
                return next;
            }
            if (SameKey(keys_[s - 1], key)) {
                *inserted = false;
                return s - 1;
            }
            i = (i + 1) & mask;
        }
    };
    for (const Triangle& t : triangles) {
        Vec3f face_normal(0, 0, 1);
        if (normals) {
            Vec3f n = Cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
            float len = Length(n);
            if (len > 0 && std::isfinite(len)) face_normal = n / len;
        }
        uint32_t idx[3];
        for (int j = 0; j < 3; ++j) {
            VertexKey k{};
            k.q = grid.Quantize(t.p[j]);
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
            idx[j] = find(k, &inserted);
            if (inserted) {
                Vec3f p = grid.Dequantize(k.q);
                mesh.positions.push_back(p);
                out.bounds.Extend(p);
                if (normals) mesh.normals.push_back(n);
                if (uvs) mesh.uvs.push_back(uv);
            }
        }
        const Vec3i &a = keys_[idx[0]].q, &b = keys_[idx[1]].q, &c = keys_[idx[2]].q;
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
