#pragma once
// The density of a participating medium over space (scene/media/medium.h): constant in a box, or a
// grid of voxels from OpenVDB (vdb_density.h), whole or one brick's piece of it. What light
// transport needs of it is exact integrals along rays: a medium's transmittance is
// exp(-σt ∫ density ds) (Beer-Lambert), and the distance to a sampled scattering is where that
// integral reaches a sampled value, so a density that is constant per voxel is integrated exactly,
// voxel by voxel. A field lives with the bricks: a brick's piece of a stored grid is loaded and
// evicted with the brick (ResidentBrick::medium).

#include <limits>
#include <memory>

#include "src/core/vecmath.h"

namespace nave::render {

class DensityField {
  public:
    virtual ~DensityField() = default;
    /// World box outside which the density is 0.
    virtual Bounds3f bounds() const = 0;
    /// Walks o + t d (d unit) from t = `t0` to `t1`: returns the t at which ∫_t0^t density ds
    /// reaches `target` (> 0, may be infinity), or infinity when it does not by t1. `*integral`
    /// receives the integral walked: `target` when it was reached, else over all of [t0, t1]. In
    /// metres at density 1. Thread-safe.
    virtual float Walk(const Vec3f& o, const Vec3f& d, float t0, float t1, float target,
                       float* integral) const = 0;
    /// The density at point `p`. Thread-safe.
    virtual float Density(const Vec3f& p) const = 0;
    /// A length over which the density may change (a voxel's side), or a fraction of the field's
    /// size where it does not: the step of points sampled along a ray through it.
    virtual float detail_m() const = 0;

    /// ∫ density ds over t in [t0, t1].
    float Integral(const Vec3f& o, const Vec3f& d, float t0, float t1) const {
        float integral = 0;
        Walk(o, d, t0, t1, std::numeric_limits<float>::infinity(), &integral);
        return integral;
    }
    /// The t in [t0, t1] at which ∫_t0^t density ds reaches `target`, or infinity.
    float Reach(const Vec3f& o, const Vec3f& d, float t0, float t1, float target) const {
        float integral = 0;
        return Walk(o, d, t0, t1, target, &integral);
    }
};

/// Density 1 inside a box, 0 outside: a homogeneous medium.
class BoxDensity final : public DensityField {
  public:
    explicit BoxDensity(const Bounds3f& box) : box_(box) {}
    Bounds3f bounds() const override { return box_; }
    float Density(const Vec3f& p) const override { return box_.Contains(p) ? 1.f : 0.f; }
    /// Constant inside: 1/64 of the box's diagonal.
    float detail_m() const override { return Length(box_.Diagonal()) / 64; }
    float Walk(const Vec3f& o, const Vec3f& d, float t0, float t1, float target,
               float* integral) const override {
        constexpr float kNever = std::numeric_limits<float>::infinity();
        float a, b;
        if (!(t1 > t0) || !ClipRayToBounds(box_, o, d, t0, t1, &a, &b)) {
            *integral = 0;
            return kNever;
        }
        if (a + target < b) {
            *integral = target;
            return a + target;
        }
        *integral = b - a;
        return kNever;
    }

  private:
    Bounds3f box_;
};

/// A field counted only inside `cell`, its values times `scale`: one brick's share of a field that
/// spans many, as a stored grid's piece is (MemoryBrickSource::HoldMedium).
class CellShare final : public DensityField {
  public:
    CellShare(std::shared_ptr<const DensityField> whole, const Bounds3f& cell, float scale)
        : whole_(std::move(whole)), cell_(cell), scale_(scale) {}
    Bounds3f bounds() const override {
        const Bounds3f b = whole_->bounds();
        return Bounds3f(Max(b.min, cell_.min), Min(b.max, cell_.max));
    }
    float Density(const Vec3f& p) const override {
        return cell_.Contains(p) ? scale_ * whole_->Density(p) : 0.f;
    }
    float detail_m() const override { return whole_->detail_m(); }
    float Walk(const Vec3f& o, const Vec3f& d, float t0, float t1, float target,
               float* integral) const override {
        float a, b;
        *integral = 0;
        if (!(t1 > t0) || !(scale_ > 0) || !ClipRayToBounds(cell_, o, d, t0, t1, &a, &b))
            return std::numeric_limits<float>::infinity();
        const float t = whole_->Walk(o, d, a, b, target / scale_, integral);
        *integral *= scale_;
        return t;
    }

  private:
    std::shared_ptr<const DensityField> whole_;
    Bounds3f cell_;
    float scale_;
};

}  // namespace nave::render
