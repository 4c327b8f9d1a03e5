#include "src/imaging/oiio_plugin.h"

#include "src/core/plugin_loader.h"

namespace nave::imaging {

StatusOr<const OiioPlugin*> LoadOiioPlugin() {
    static const StatusOr<void*> plugin =
        LoadPlugin({"the OpenImageIO plugin", "NAVE_OIIO_PLUGIN", "libnave_oiio.so",
                    NAVE_OIIO_PLUGIN_BUILD_PATH, "NaveCreateOiioPlugin", kOiioPluginVersion},
                   [](void* factory, int version) -> void* {
                       return reinterpret_cast<OiioPlugin* (*)(int)>(factory)(version);
                   });
    if (!plugin.ok()) return plugin.status();
    return static_cast<const OiioPlugin*>(*plugin);
}

}  // namespace nave::imaging
