#pragma once
// The density of a participating medium over space (scene/media/medium.h): constant in a box, or a
// grid of voxels read from an OpenVDB file (vdb_density.h). What light transport needs of it is
// exact integrals along rays: a medium's transmittance is exp(-σt ∫ density ds) (Beer-Lambert),
// and the distance to a sampled scattering is where that integral reaches a sampled value, so a
// density that is constant per voxel is integrated exactly, voxel by voxel.

#include <limits>

#include "src/core/vecmath.h"

namespace nave::render {

class DensityField {
  public:
    virtual ~DensityField() = default;
    /// World box outside which the density is 0.
    virtual Bounds3f bounds() const = 0;
    /// ∫ density ds along o + t d (d unit), t in [0, t_max]: in metres at density 1.
    virtual float Integral(const Vec3f& o, const Vec3f& d, float t_max) const = 0;
    /// The t in [0, t_max] at which that integral reaches `target` (> 0), or infinity when it
    /// does not.
    virtual float Reach(const Vec3f& o, const Vec3f& d, float t_max, float target) const = 0;
};

/// Density 1 inside a box, 0 outside: a homogeneous medium.
class BoxDensity final : public DensityField {
  public:
    explicit BoxDensity(const Bounds3f& box) : box_(box) {}
    Bounds3f bounds() const override { return box_; }
    float Integral(const Vec3f& o, const Vec3f& d, float t_max) const override {
        float t0, t1;
        return ClipRayToBounds(box_, o, d, 0, t_max, &t0, &t1) ? t1 - t0 : 0.f;
    }
    float Reach(const Vec3f& o, const Vec3f& d, float t_max, float target) const override {
        float t0, t1;
        if (!ClipRayToBounds(box_, o, d, 0, t_max, &t0, &t1) || !(t0 + target < t1))
            return std::numeric_limits<float>::infinity();
        return t0 + target;
    }

  private:
    Bounds3f box_;
};

}  // namespace nave::render
