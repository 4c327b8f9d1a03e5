#include "preprocess/abbey/emitter.h"

#include <array>
#include <cmath>

namespace nave::preprocess::abbey {

void Emitter::Push(Triangle& t) {
    if (!IsFinite(t.p[0]) || !IsFinite(t.p[1]) || !IsFinite(t.p[2]))
        return;  // a primitive's degenerate case
    batch_.push_back(t);
    ++emitted_;
    if (batch_.size() >= batch_triangles_) Flush();
}

void Emitter::Flush() {
    if (batch_.empty()) return;
    flush_(batch_);
    batch_.clear();
}

bool Emitter::Orient(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& outward,
                     uint32_t material, Triangle* t, bool* flip) {
    Vec3d n = Cross(b - a, c - a);
    t->material = material;
    t->p[0] = Vec3f(a);
    *flip = Dot(n, outward) < 0;
    t->p[1] = Vec3f(*flip ? c : b);
    t->p[2] = Vec3f(*flip ? b : c);
    if (t->p[0] == t->p[1] || t->p[1] == t->p[2] || t->p[0] == t->p[2]) return false;
    Vec3f nf = Cross(t->p[1] - t->p[0], t->p[2] - t->p[0]);
    return Dot(nf, nf) != 0.f;
}

void Emitter::Tri(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& outward,
                  uint32_t material) {
    Triangle t;
    bool flip = false;
    if (Orient(a, b, c, outward, material, &t, &flip)) Push(t);
}

void Emitter::TriUv(const Vec3d& a, const Vec3d& b, const Vec3d& c, const std::array<float, 2>& ta,
                    const std::array<float, 2>& tb, const std::array<float, 2>& tc,
                    const Vec3d& outward, uint32_t material) {
    Triangle t;
    bool flip = false;
    if (!Orient(a, b, c, outward, material, &t, &flip)) return;
    t.uv = {ta, flip ? tc : tb, flip ? tb : tc};  // the texture coordinates follow their corners
    t.has_uvs = true;
    Push(t);
}

void Emitter::TriN(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& na, const Vec3d& nb,
                   const Vec3d& nc, const Vec3d& outward, uint32_t material) {
    Triangle t;
    bool flip = false;
    if (!Orient(a, b, c, outward, material, &t, &flip)) return;
    t.has_normals = true;
    Vec3f nf = Cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    // Shading normals face the same side as the geometric normal.
    Vec3d face = Normalize(Vec3d(nf));
    auto orient = [&](const Vec3d& v) {
        Vec3d u = Dot(v, face) < 0 ? -v : v;
        double len = Length(u);
        // A shading normal (nearly) in the triangle's plane says nothing about its front: use the
        // face's.
        if (!(len > 0) || !std::isfinite(len) || Dot(u, face) < 1e-3 * len) return Vec3f(face);
        return Vec3f(u / len);
    };
    t.n[0] = orient(na);
    t.n[1] = orient(flip ? nc : nb);
    t.n[2] = orient(flip ? nb : nc);
    Push(t);
}

}  // namespace nave::preprocess::abbey
