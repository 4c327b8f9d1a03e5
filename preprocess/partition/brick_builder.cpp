#include "preprocess/partition/brick_builder.h"

#include <bit>
#include <cmath>
#include <cstring>

namespace nave::preprocess {
namespace {

struct VertexKey {
    Vec3i q;
    uint32_t n[3];
    uint32_t uv[2];
    bool operator==(const VertexKey& o) const { return std::memcmp(this, &o, sizeof(VertexKey)) == 0; }
};

uint64_t HashKey(const VertexKey& k) {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    auto mix = [&](uint32_t v) {
        h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
    };
    mix(uint32_t(k.q.x));
    mix(uint32_t(k.q.y));
    mix(uint32_t(k.q.z));
    for (uint32_t v : k.n) mix(v);
    mix(k.uv[0]);
    mix(k.uv[1]);
    return h ^ (h >> 29);
}

// Open addressing, linear probing; slots hold vertex index + 1 (0 = empty).
class VertexTable {
  public:
    explicit VertexTable(size_t expected) {
        size_t cap = 16;
        while (cap < expected * 2) cap <<= 1;
        slots_.assign(cap, 0);
        mask_ = cap - 1;
    }
    // Returns the index of `key`, inserting `next` if absent (then *inserted = true).
    uint32_t Find(const VertexKey& key, const std::vector<VertexKey>& keys, uint32_t next, bool* inserted) {
        size_t i = HashKey(key) & mask_;
        while (true) {
            uint32_t s = slots_[i];
            if (s == 0) {
                slots_[i] = next + 1;
                *inserted = true;
                return next;
            }
            if (keys[s - 1] == key) {
                *inserted = false;
                return s - 1;
            }
            i = (i + 1) & mask_;
        }
    }

  private:
    std::vector<uint32_t> slots_;
    size_t mask_ = 0;
};

}  // namespace

BuiltBrick BuildBrickMesh(const std::vector<Triangle>& triangles, const store::GlobalGrid& grid) {
    BuiltBrick out;
    bool normals = false, uvs = false;
    for (const Triangle& t : triangles) {
        normals |= t.has_normals;
        uvs |= t.has_uvs;
    }
    store::BrickMesh& mesh = out.mesh;
    std::vector<VertexKey> keys;
    keys.reserve(triangles.size());
    mesh.positions.reserve(triangles.size());
    if (normals) mesh.normals.reserve(triangles.size());
    if (uvs) mesh.uvs.reserve(triangles.size());
    mesh.indices.reserve(triangles.size() * 3);
    mesh.material_ids.reserve(triangles.size());
    VertexTable table(triangles.size() + 16);
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
                // Bad input normals (zero, NaN, not unit) are replaced or renormalised, not passed on.
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
            uint32_t next = uint32_t(keys.size());
            idx[j] = table.Find(k, keys, next, &inserted);
            if (inserted) {
                keys.push_back(k);
                Vec3f p = grid.Dequantize(k.q);
                mesh.positions.push_back(p);
                out.bounds.Extend(p);
                if (normals) mesh.normals.push_back(n);
                if (uvs) mesh.uvs.push_back(uv);
            }
        }
        if (keys[idx[0]].q == keys[idx[1]].q || keys[idx[1]].q == keys[idx[2]].q || keys[idx[0]].q == keys[idx[2]].q) {
            ++out.collapsed_triangles;
            continue;
        }
        mesh.indices.insert(mesh.indices.end(), {idx[0], idx[1], idx[2]});
        mesh.material_ids.push_back(t.material);
    }
    return out;
}

}  // namespace nave::preprocess
