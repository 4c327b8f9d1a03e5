#include "preprocess/import/ifc_plugin.h"

#include "src/core/plugin_loader.h"

namespace nave::preprocess {

StatusOr<const IfcPlugin*> LoadIfcPlugin() {
#ifdef NAVE_IFC_PLUGIN_BUILD_PATH
    static const StatusOr<void*> plugin =
        LoadPlugin({"the IFC plugin", "NAVE_IFC_PLUGIN", "libnave_ifc.so",
                    NAVE_IFC_PLUGIN_BUILD_PATH, "NaveCreateIfcPlugin", kIfcPluginVersion},
                   [](void* factory, int version) -> void* {
                       return reinterpret_cast<IfcPlugin* (*)(int)>(factory)(version);
                   });
    if (!plugin.ok()) return plugin.status();
    return static_cast<const IfcPlugin*>(*plugin);
#else
    return UnsupportedError(
        "this nave was built without IFC++, so IFC files are off: install libifcplusplus-dev "
        "(scripts/setup-debian.sh) and build again");
#endif
}

bool IfcPluginBuilt() {
#ifdef NAVE_IFC_PLUGIN_BUILD_PATH
    return true;
#else
    return false;
#endif
}

}  // namespace nave::preprocess
