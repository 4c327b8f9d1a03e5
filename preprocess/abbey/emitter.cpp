#include "preprocess/abbey/emitter.h"

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

void Emitter::Tri(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& outward,
                  uint32_t material) {
    Vec3d n = Cross(b - a, c - a);
    Triangle t;
    t.material = material;
    t.p[0] = Vec3f(a);
    bool flip = Dot(n, outward) < 0;
    t.p[1] = Vec3f(flip ? c : b);
    t.p[2] = Vec3f(flip ? b : c);
    if (t.p[0] == t.p[1] || t.p[1] == t.p[2] || t.p[0] == t.p[2]) return;
    Vec3f nf = Cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    if (Dot(nf, nf) == 0.f) return;
    Push(t);
}

void Emitter::TriN(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& na, const Vec3d& nb,
                   const Vec3d& nc, const Vec3d& outward, uint32_t material) {
    Vec3d n = Cross(b - a, c - a);
    bool flip = Dot(n, outward) < 0;
    Triangle t;
    t.material = material;
    t.has_normals = true;
    t.p[0] = Vec3f(a);
    t.p[1] = Vec3f(flip ? c : b);
    t.p[2] = Vec3f(flip ? b : c);
    if (t.p[0] == t.p[1] || t.p[1] == t.p[2] || t.p[0] == t.p[2]) return;
    Vec3f nf = Cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    if (Dot(nf, nf) == 0.f) return;
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
