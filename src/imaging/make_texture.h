#pragma once
// Texture files as the renderer reads them best: tiled (64x64) and MIP-mapped, written by
// OpenImageIO's make_texture (in nave's plugin, imaging/oiio_plugin.h).

#include <filesystem>

#include "src/core/status.h"
#include "src/imaging/oiio_plugin.h"

namespace nave::imaging {

/// Converts `source` into a tiled, MIP-mapped texture at `output` (format by extension: ".exr" for
/// colour,
/// ".tx" TIFF for data). Colour is decoded from sRGB to linear and kept in half floats; data keeps
/// its values and pixel type. Problems with the source are NotFound (missing) or InvalidArgument
/// (unreadable), naming it; a failure to write `output` is IoError naming it. `output` is written
/// in place: give a temporary name.
Status MakeTiledTexture(const std::filesystem::path& source, const std::filesystem::path& output,
                        TextureContent content);

}  // namespace nave::imaging
