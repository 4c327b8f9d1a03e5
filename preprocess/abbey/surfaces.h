#pragma once
// Floors of glazed tiles and roofs of slates: surfaces covered with many small units, each a
// slightly raised, bevelled plate (n x n grid at detail D, see detail.h).

#include <functional>

#include "preprocess/abbey/detail.h"
#include "preprocess/abbey/emitter.h"
#include "src/core/vecmath.h"

namespace nave::preprocess::abbey {

/// Tiles the rectangle [x0, x1] x [y0, y1] at z = 0 with square tiles in a checkerboard of the two
/// floor materials, keeping those whose centre satisfies `inside` (the church's plan), over a
/// bedding plane.
void EmitTiledFloor(Emitter& em, double x0, double x1, double y0, double y1,
                    const std::function<bool(double, double)>& inside, const Detail& detail);

/// Covers a roof surface R(s, t) (s along the eaves, t up the slope, both in [0, 1]; `length_s` and
/// `length_t` its sizes in metres) with overlapping slates, over a sealing deck; `up` is the side
/// the roof faces (away from the building).
void EmitSlateRoof(Emitter& em, const std::function<Vec3d(double, double)>& roof, double length_s,
                   double length_t, const std::function<Vec3d(const Vec3d&)>& up,
                   const Detail& detail, uint64_t seed);

}  // namespace nave::preprocess::abbey
