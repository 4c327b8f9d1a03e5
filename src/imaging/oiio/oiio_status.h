#pragma once
// The one adapter from OpenImageIO's error reporting (geterror() strings after a failed call) to
// nave's Status. Private to the plugin (src/imaging/oiio): it includes OIIO.

#include <OpenImageIO/texture.h>

#include <filesystem>
#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave::imaging::oiio {

/// A Status for a failed OIIO call on `file`: "<file>: <what>: <OIIO's message>". `oiio_message`
/// is the text of geterror() (already cleared by the caller); a missing file becomes NotFound, an
/// unreadable one IoError. Never returns Ok.
Status OiioError(const std::filesystem::path& file, std::string_view what,
                 std::string oiio_message);

/// Takes (and clears) the pending error of `ts` and, if empty, OIIO's global error.
std::string TakeError(OIIO::TextureSystem& ts);

}  // namespace nave::imaging::oiio
