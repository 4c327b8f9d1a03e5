#include "src/core/plugin_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

namespace nave {

StatusOr<void*> LoadPlugin(const PluginSpec& spec, void* (*make)(void* factory, int version)) {
    std::vector<std::string> candidates;
    if (const char* env = std::getenv(spec.env.c_str())) candidates.push_back(env);
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) candidates.push_back((exe.parent_path() / spec.file).string());
    candidates.push_back(spec.build_path);
    candidates.push_back(spec.file);
    std::string tried;
    for (const std::string& c : candidates) {
        // Kept loaded for the life of the process: what the plugin made may live until exit.
        void* handle = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (handle == nullptr) {
            tried += "\n  " + c + ": " + dlerror();
            continue;
        }
        void* create = dlsym(handle, spec.factory.c_str());
        if (create == nullptr) {
            tried += "\n  " + c + ": no " + spec.factory + " (not a nave plugin, or too old)";
            continue;
        }
        if (void* plugin = make(create, spec.version)) return plugin;
        tried +=
            fmt::format("\n  {}: built for another version of nave (expected plugin version {})", c,
                        spec.version);
    }
    return InternalError("cannot load {} {} (set {}); tried:{}", spec.what, spec.file, spec.env,
                         tried);
}

}  // namespace nave
