#pragma once
// Where the abbey's geometry goes: an Emitter collects triangles and hands them on in batches.
// Every face is given with the direction it must face ("outward": away from the solid, towards the
// space a visitor stands in), and the emitter orders the corners so that the winding agrees, which
// keeps normals consistent without each primitive having to get its vertex order right.

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "preprocess/triangle_source.h"
#include "src/core/vecmath.h"

namespace nave::preprocess::abbey {

class Emitter {
  public:
    /// `flush` receives full batches (and the last partial one from Flush()).
    Emitter(std::function<void(std::vector<Triangle>&)> flush, size_t batch_triangles)
        : flush_(std::move(flush)), batch_triangles_(batch_triangles) {
        batch_.reserve(batch_triangles_);
    }

    /// A triangle whose front faces `outward` (corners reordered if needed). Zero-area triangles
    /// are dropped.
    void Tri(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& outward,
             uint32_t material);
    /// The same with shading normals (flipped with the corners if needed: normals follow
    /// `outward`).
    void TriN(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& na, const Vec3d& nb,
              const Vec3d& nc, const Vec3d& outward, uint32_t material);
    /// The same with texture coordinates (reordered with the corners if needed).
    void TriUv(const Vec3d& a, const Vec3d& b, const Vec3d& c, const std::array<float, 2>& ta,
               const std::array<float, 2>& tb, const std::array<float, 2>& tc, const Vec3d& outward,
               uint32_t material);
    /// A planar-ish quad a b c d (in order around it), split along a-c.
    void Quad(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, const Vec3d& outward,
              uint32_t material) {
        Tri(a, b, c, outward, material);
        Tri(a, c, d, outward, material);
    }
    void QuadN(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, const Vec3d& na,
               const Vec3d& nb, const Vec3d& nc, const Vec3d& nd, const Vec3d& outward,
               uint32_t material) {
        TriN(a, b, c, na, nb, nc, outward, material);
        TriN(a, c, d, na, nc, nd, outward, material);
    }

    void QuadUv(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d,
                const std::array<std::array<float, 2>, 4>& uv, const Vec3d& outward,
                uint32_t material) {
        TriUv(a, b, c, uv[0], uv[1], uv[2], outward, material);
        TriUv(a, c, d, uv[0], uv[2], uv[3], outward, material);
    }

    /// Hands the pending triangles on.
    void Flush();
    uint64_t emitted() const { return emitted_; }

  private:
    /// Fills `t` with a b c, wound to face `outward` (`flip`: b and c swapped); false if
    /// degenerate.
    static bool Orient(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& outward,
                       uint32_t material, Triangle* t, bool* flip);
    void Push(Triangle& t);
    std::function<void(std::vector<Triangle>&)> flush_;
    size_t batch_triangles_;
    std::vector<Triangle> batch_;
    uint64_t emitted_ = 0;
};

}  // namespace nave::preprocess::abbey
