#pragma once
// Round piers in the manner of early Gothic naves: an octagonal plinth, an Attic base (torus,
// scotia, torus), a shaft built of drums with chamfered joints, an astragal, a bell capital with
// crockets and an octagonal abacus.

#include "preprocess/abbey/detail.h"
#include "preprocess/abbey/emitter.h"
#include "src/core/vecmath.h"

namespace nave::preprocess::abbey {

struct PierSpec {
    Vec3d base;           ///< centre of the plinth's bottom (on the floor)
    double radius = 0.8;  ///< shaft radius, metres
    double top = 8.75;    ///< height of the abacus top (where the arches spring), metres
    uint64_t seed = 0;
};

void EmitPier(Emitter& em, const PierSpec& pier, const Detail& detail);

}  // namespace nave::preprocess::abbey
