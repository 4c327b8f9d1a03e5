#include "preprocess/import/cad_plugin.h"

#include "src/core/plugin_loader.h"

namespace nave::preprocess {

bool CadPluginBuilt() {
#ifdef NAVE_CAD_PLUGIN_BUILD_PATH
    return true;
#else
    return false;
#endif
}

StatusOr<const CadPlugin*> LoadCadPlugin() {
#ifdef NAVE_CAD_PLUGIN_BUILD_PATH
    static const StatusOr<void*> plugin =
        LoadPlugin({"the CAD plugin", "NAVE_CAD_PLUGIN", "libnave_cad.so",
                    NAVE_CAD_PLUGIN_BUILD_PATH, "NaveCreateCadPlugin", kCadPluginVersion},
                   [](void* factory, int version) -> void* {
                       return reinterpret_cast<CadPlugin* (*)(int)>(factory)(version);
                   });
    if (!plugin.ok()) return plugin.status();
    return static_cast<const CadPlugin*>(*plugin);
#else
    return UnsupportedError(
        "this nave was built without Open CASCADE, so STEP and IGES files are off: install "
        "libocct-data-exchange-dev and libocct-modeling-algorithms-dev (scripts/setup-debian.sh) "
        "and build again");
#endif
}

}  // namespace nave::preprocess
