#pragma once
// Shared by the fuzz targets whose code under test reads from a path (the importers, the store
// reader): the input is written to a file in a scratch directory owned by this process, removed at
// exit. libFuzzer calls the target from one thread, so one file per name is enough.

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace nave::fuzz {

/// This process's scratch directory under $TMPDIR (scripts/fuzz.sh points it at /dev/shm when it
/// can: every input is written once per execution).
inline const std::filesystem::path& ScratchDir() {
    static const std::filesystem::path dir = [] {
        std::filesystem::path d =
            std::filesystem::temp_directory_path() / ("nave_fuzz_" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(ScratchDir(), ec);
        });
        return d;
    }();
    return dir;
}

/// Writes `bytes` to `name` in the scratch directory and returns its path.
inline std::filesystem::path WriteInput(const std::string& name, std::string_view bytes) {
    const std::filesystem::path path = ScratchDir() / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    return path;
}

inline std::string_view AsView(const uint8_t* data, size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

}  // namespace nave::fuzz
