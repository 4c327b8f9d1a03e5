#pragma once
// Geometric building blocks of the abbey: boxes, chamfered stones with tooled faces, surfaces of
// revolution (piers, bases, capitals), profiles swept along curves (ribs, arch mouldings) and
// parametric surfaces (vault webs). Each takes the tessellation it should use, so that detail
// scales the whole model.

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "preprocess/abbey/emitter.h"

namespace nave::preprocess::abbey {

struct Vec2 {
    double x = 0, y = 0;
};

/// A deterministic hash of integers to [0, 1): the abbey's only source of variation (same detail,
/// same model).
double Hash01(uint64_t a, uint64_t b = 0, uint64_t c = 0);

/// The shape of a pointed (two-centred) arch, normalised: t = 0 at the crown, 1 at the springing;
/// returns the height as a fraction of the rise, in [0, 1]. `rho` is the radius of each arc over
/// the half-span (1 = round arch, 2 = equilateral arch, the usual Gothic choice). Each half is an
/// arc of a circle of radius rho centred on the springing line at distance rho - 1 beyond the crown
/// axis: height = sqrt(rho^2 - (t + rho - 1)^2), divided by its crown value sqrt(2 rho - 1).
double PointedArch(double t, double rho);

/// An axis-aligned box, all six faces outward.
void Box(Emitter& em, const Vec3d& lo, const Vec3d& hi, uint32_t material);
/// A box centred at `c` with half-axis vectors a, b, c (orthogonal).
void OrientedBox(Emitter& em, const Vec3d& center, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                 uint32_t material);

/// A local frame: point = origin + u * x + v * y + w * z.
struct Frame {
    Vec3d origin, u, v, w;
    Vec3d At(double x, double y, double z = 0) const { return origin + u * x + v * y + w * z; }
};

struct StoneStyle {
    double joint = 0.008;     ///< half the mortar joint, metres
    double relief = 0.02;     ///< how far the stone face stands out of the wall face, metres
    double chamfer = 0.015;   ///< width of the bevel round the face, metres
    double tooling = 0.0015;  ///< amplitude of the tooled face's relief, metres
    int subdivisions = 1;     ///< the face is a grid of n x n quads (detail)
};

/// One ashlar stone on a wall face: the rectangle [0, lu] x [0, lv] of `f`'s (u, v) plane, standing
/// out along f.w. Front face (tooled, `subdivisions` squared quads) and four chamfers: 2 n^2 + 8 n
/// triangles.
void Stone(Emitter& em, const Frame& f, double lu, double lv, const StoneStyle& style,
           uint64_t seed, uint32_t material);

/// A surface of revolution around the vertical through `base`: `profile` is (radius, height) from
/// the bottom up; faces point away from the axis side of the profile (a profile going up with r > 0
/// faces outward). `segments` around; `sides` > 0 makes a polygon (octagonal abacus) instead of a
/// circle.
void Revolve(Emitter& em, const Vec3d& base, const std::vector<Vec2>& profile, int segments,
             uint32_t material, int sides = 0, double phase = 0);

/// Sweeps a closed profile (b, n) (counter-clockwise) along `path`: b along `side` (a constant unit
/// vector perpendicular to the path's plane), n along the in-plane normal. Ends capped.
void Sweep(Emitter& em, const std::vector<Vec3d>& path, const Vec3d& side,
           const std::vector<Vec2>& profile, uint32_t material, bool caps = true);

/// A grid over a parametric surface P(s, t), s and t in [0, 1], with `ns` x `nt` quads and smooth
/// normals from the derivatives, facing the side `outward(point)` points to.
void ParamGrid(Emitter& em, const std::function<Vec3d(double, double)>& p, int ns, int nt,
               const std::function<Vec3d(const Vec3d&)>& outward, uint32_t material);

/// A circle of `n` points in the profile plane (for tubes).
std::vector<Vec2> CircleProfile(double radius, int n, double center_n = 0);

}  // namespace nave::preprocess::abbey
