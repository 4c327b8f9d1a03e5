#pragma once
// Masonry walls with pointed-arch openings: arcades (open to the floor or to the springing), lancet
// windows glazed with stained-glass panes in lead cames, portals with wooden doors. Both faces are
// laid in ashlar courses of individual chamfered stones; the reveals, sills and soffits are cut
// through the thickness.

#include <cstdint>
#include <vector>

#include "preprocess/abbey/detail.h"
#include "preprocess/abbey/emitter.h"
#include "src/core/vecmath.h"

namespace nave::preprocess::abbey {

enum class OpeningKind { kOpen, kWindow, kDoor };

/// An opening [center - half_width, center + half_width] along the wall, from `sill` up to a
/// pointed arch springing at `spring` and rising `rise` more. All in metres (center along the wall
/// from its start).
struct Opening {
    double center = 0, half_width = 1, sill = 0, spring = 2, rise = 1;
    OpeningKind kind = OpeningKind::kOpen;
    bool moulded = true;  ///< a roll moulding round the arch on both faces
    double rho = 2.0;     ///< arch radius over half-span (2: equilateral)
    /// Windows: how much wider (metres, each side) the opening is on both faces than in the glass
    /// plane; the jambs and the arch splay out to the faces (a scaled copy of the arch round the
    /// springing's centre, the sill level), so that slanting sunlight reaches the glass and, past
    /// it, the floor through a thick wall.
    double splay = 0;
    /// Windows: how far (metres) the sill slopes down from the glass to the interior face (a
    /// glacis), so that light falling steeply through the glass is not stopped by a flat sill.
    double glacis = 0;
    /// The opening's outline on the interior (`inner`) or exterior face of the wall: splayed and,
    /// inside, with the foot of its glacis (the opening itself when neither applies).
    Opening AtFace(bool inner) const;
    double Top(double u) const;
    /// Half the opening's width at height z (0 above the apex).
    double HalfWidthAt(double z) const;
};

struct WallSpec {
    Vec3d origin;  ///< interior face, at the wall's start, at z = 0
    Vec3d along;   ///< unit, horizontal
    Vec3d inward;  ///< unit, horizontal: the interior face faces this way
    double length = 1, z0 = 0, z1 = 1, thickness = 1;
    std::vector<Opening>
        openings;  ///< sorted by center, within the wall, at most one per column (their
                   ///< horizontal spans disjoint: stack storeys as separate walls)
    bool stones_inside = true, stones_outside = true;
    bool close_ends = true;
    uint32_t material = 0;
    uint64_t seed = 0;  ///< varies stone lengths and glass colours
};

void EmitWall(Emitter& em, const WallSpec& wall, const Detail& detail);

}  // namespace nave::preprocess::abbey
