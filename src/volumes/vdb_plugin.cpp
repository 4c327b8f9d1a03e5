#include "src/volumes/vdb_plugin.h"

#include "src/core/plugin_loader.h"

namespace nave::volumes {

StatusOr<const VdbPlugin*> LoadVdbPlugin() {
    static const StatusOr<void*> plugin =
        LoadPlugin({"the OpenVDB plugin", "NAVE_VDB_PLUGIN", "libnave_vdb.so",
                    NAVE_VDB_PLUGIN_BUILD_PATH, "NaveCreateVdbPlugin", kVdbPluginVersion},
                   [](void* factory, int version) -> void* {
                       return reinterpret_cast<VdbPlugin* (*)(int)>(factory)(version);
                   });
    if (!plugin.ok()) return plugin.status();
    return static_cast<const VdbPlugin*>(*plugin);
}

}  // namespace nave::volumes
