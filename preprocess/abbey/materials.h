#pragma once
// The abbey's materials: the names every nave render config maps (see docs/abbey.md).

#include <cstdint>
#include <vector>

#include "store/material_record.h"

namespace nave::preprocess::abbey {

enum Material : uint32_t {
    kLimestone = 0,
    kLimestoneDark,  ///< capitals, ribs, bosses
    kFloorLight,
    kFloorDark,
    kGlassClear,
    kGlassBlue,
    kGlassRed,
    kGlassYellow,
    kGlassGreen,
    kLead,
    kWood,
    kRoofSlate,
    kMaterialCount
};

/// The material table, indexed by Material.
std::vector<store::MaterialRecord> AbbeyMaterials();

}  // namespace nave::preprocess::abbey
