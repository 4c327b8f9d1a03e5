#include "src/imaging/oiio_plugin.h"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <system_error>

namespace nave::imaging {

StatusOr<const OiioPlugin*> LoadOiioPlugin() {
    static const OiioPlugin* plugin = nullptr;
    static Status status;
    static std::once_flag once;
    std::call_once(once, [] {
        std::vector<std::string> candidates;
        if (const char* env = std::getenv("NAVE_OIIO_PLUGIN")) candidates.push_back(env);
        std::error_code ec;
        std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
        if (!ec) candidates.push_back((exe.parent_path() / "libnave_oiio.so").string());
        candidates.push_back(NAVE_OIIO_PLUGIN_BUILD_PATH);
        candidates.push_back("libnave_oiio.so");
        std::string tried;
        for (const std::string& c : candidates) {
            // Kept loaded for the life of the process: textures and caches it made may live until
            // exit.
            void* handle = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (handle == nullptr) {
                tried += "\n  " + c + ": " + dlerror();
                continue;
            }
            auto create =
                reinterpret_cast<OiioPlugin* (*)(int)>(dlsym(handle, "NaveCreateOiioPlugin"));
            if (create == nullptr) {
                tried += "\n  " + c + ": no NaveCreateOiioPlugin (not a nave plugin, or too old)";
                continue;
            }
            plugin = create(kOiioPluginVersion);
            if (plugin != nullptr) return;
            tried += fmt::format(
                "\n  {}: built for another version of nave (expected plugin version {})", c,
                kOiioPluginVersion);
        }
        status = InternalError(
            "cannot load the OpenImageIO plugin libnave_oiio.so (set NAVE_OIIO_PLUGIN); "
            "tried:{}",
            tried);
    });
    if (plugin == nullptr) return status;
    return plugin;
}

}  // namespace nave::imaging
