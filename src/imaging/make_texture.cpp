#include "src/imaging/make_texture.h"

namespace nave::imaging {

Status MakeTiledTexture(const std::filesystem::path& source, const std::filesystem::path& output,
                        TextureContent content) {
    NAVE_ASSIGN_OR_RETURN(const OiioPlugin* plugin, LoadOiioPlugin());
    return plugin->MakeTexture(source, output, content);
}

}  // namespace nave::imaging
