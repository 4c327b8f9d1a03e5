#pragma once
// An orthonormal shading frame: BSDFs work in local coordinates where the normal is +z.

#include <cmath>

#include "src/core/vecmath.h"

namespace nave {

/// Three orthonormal vectors x, y, z (right-handed). ToLocal/FromLocal change coordinates.
struct Frame {
    Vec3f x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};

    Frame() = default;
    Frame(const Vec3f& x_, const Vec3f& y_, const Vec3f& z_) : x(x_), y(y_), z(z_) {}

    /// A frame whose z is the unit vector `n` (Duff et al. 2017, "Building an orthonormal basis,
    /// revisited", JCGT 6(1), listing 3: branchless, continuous except at n.z = -1 exactly).
    static Frame FromZ(const Vec3f& n) {
        float sign = std::copysign(1.f, n.z);
        float a = -1.f / (sign + n.z);
        float b = n.x * n.y * a;
        return Frame(Vec3f(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x),
                     Vec3f(b, sign + n.y * n.y * a, -n.y), n);
    }
    /// A frame with z = unit `n` and x along the part of `tangent` orthogonal to n (Gram-Schmidt);
    /// falls back to FromZ if the tangent is parallel to n.
    static Frame FromZTangent(const Vec3f& n, const Vec3f& tangent) {
        Vec3f t = tangent - n * Dot(n, tangent);
        float len = Length(t);
        if (!(len > 1e-6f)) return FromZ(n);
        t = t / len;
        return Frame(t, Cross(n, t), n);
    }

    Vec3f ToLocal(const Vec3f& v) const { return {Dot(v, x), Dot(v, y), Dot(v, z)}; }
    Vec3f FromLocal(const Vec3f& v) const { return x * v.x + y * v.y + z * v.z; }
};

}  // namespace nave
