#pragma once
// Spectral transmittance maps of the abbey's stained glass. The origin paper measured the
// transmittance of Royaumont's glass band by band; nave gives every glass colour of the procedural
// abbey a multi-band OpenEXR map of its internal transmittance (one channel per 20 nm band, band
// centres in the header attribute imaging::kBandCentresAttribute) that spans a whole window
// (texture coordinates in wall.cpp: origin top-left, s across, t down). The map varies with the
// glass's thickness, as blown medieval glass does across a pane. The renderer's thin glass takes
// its internal transmittance from it (docs/textures.md).

#include <filesystem>
#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave::preprocess::abbey {

/// The texture slot naming a thin glass pane's spectral internal-transmittance map.
inline constexpr char kTransmittanceSlot[] = "nave:transmittance";

/// The file name of glass material `material`'s map ("glass_blue.transmittance.exr").
std::string GlassTextureName(std::string_view material);

/// Writes the maps of the five glass colours into `dir` (tiled half-float OpenEXR, 96 x 192 texels,
/// 21 bands 380-780 nm). Errors name the file.
Status WriteGlassTextures(const std::filesystem::path& dir);

}  // namespace nave::preprocess::abbey
