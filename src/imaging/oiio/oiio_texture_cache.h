#pragma once
// TextureCache over OpenImageIO's TextureSystem. Private to the plugin.

#include <memory>

#include "src/imaging/texture_cache.h"

namespace nave::imaging::oiio {

/// Creates a cache with its own (unshared) TextureSystem and ImageCache.
StatusOr<std::unique_ptr<TextureCache>> CreateOiioTextureCache(size_t max_memory_bytes);

}  // namespace nave::imaging::oiio
