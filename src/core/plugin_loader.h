#pragma once
// Loading one of nave's plugins: shared modules built beside the executable that hold a library
// too heavy to link into every command (OpenImageIO: src/imaging/oiio_plugin.h; OpenVDB:
// src/volumes/vdb_plugin.h). Each exports one factory function taking the plugin interface's
// version.

#include <string>

#include "src/core/status.h"

namespace nave {

/// Where a plugin is looked for and what it exports.
struct PluginSpec {
    std::string what;  ///< "the OpenImageIO plugin", for messages
    std::string env;   ///< environment variable naming its file, tried first
    std::string file;  ///< its file name, tried beside the executable, then on the search path
    std::string build_path;  ///< its path in the build tree
    std::string factory;     ///< the exported factory's name
    int version = 0;         ///< the interface version the factory must accept
};

/// Calls `make(factory, spec.version)` with the exported factory of each candidate in turn (`make`
/// casts it to its real type and calls it) and returns the first plugin made, null meaning the
/// candidate refused the version. The plugin and its module are kept for the life of the process.
/// An error lists every place tried and why each failed.
StatusOr<void*> LoadPlugin(const PluginSpec& spec, void* (*make)(void* factory, int version));

}  // namespace nave
