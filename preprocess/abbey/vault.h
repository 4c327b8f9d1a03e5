#pragma once
// Rib vaults. A quadripartite bay is modelled as two intersecting pointed barrels: over the bay's
// parameter square (u, v) in [-1, 1]^2 the intrados is at z = spring + rise * PointedArch(min(|u|,
// |v|)), so the groins fall exactly on the diagonals, where the diagonal ribs run; transverse
// arches run along u = +-1. Apses and chapels get ribbed half-domes with the same pointed profile
// along each radius.

#include <array>

#include "preprocess/abbey/detail.h"
#include "preprocess/abbey/emitter.h"
#include "src/core/vecmath.h"

namespace nave::preprocess::abbey {

struct VaultBay {
    /// Plan corners at (u, v) = (-1, -1), (1, -1), (1, 1), (-1, 1); bilinear in between (trapezoids
    /// allowed).
    std::array<Vec3d, 4> corners;  ///< z ignored
    double spring = 20, rise = 8, thickness = 0.3;
    bool rib_u_min = true, rib_u_max = false;  ///< transverse arches at u = -1 / +1
    uint64_t seed = 0;
};

void EmitVaultBay(Emitter& em, const VaultBay& bay, const Detail& detail);

/// A lunette: the web of a half-dome's sector lifted round the clerestory window in the middle of
/// the sector's wall, as a pointed barrel running from the wall toward the centre (its crown
/// horizontal), fading into the dome from `fade_from` (a fraction of the radius) outward, so that
/// light from the window reaches the floor instead of the back of the web.
struct Lunette {
    double half_width = 0;  ///< metres, across the sector at its centre line; 0: no lunette
    double crown = 0;       ///< height of the lunette's crown (its springing is the dome's)
    double fade_from = 0.4;
};

/// A ribbed half-dome over the half-disc of `radius` round `center` (z = 0) facing `axis` (unit,
/// horizontal), `ribs` radial ribs evenly spread over the half circle (ends excluded), each of the
/// ribs + 1 sectors with `lunette` round its window.
void EmitHalfDome(Emitter& em, const Vec3d& center, const Vec3d& axis, double radius, double spring,
                  double rise, int ribs, const Detail& detail, const Lunette& lunette = {});

}  // namespace nave::preprocess::abbey
