#include "render/image_io.h"

#include <dlfcn.h>
#include <unistd.h>

#include <atomic>
#include <mutex>
#include <system_error>

namespace nave::render {
namespace {

using WriteFn = int (*)(const char*, const char*, int, int, int, const char* const*, const int*, int, const void*,
                        int, const char* const*, const char* const*, char*, size_t);
using ReadFn = int (*)(const char*, int*, int*, int*, char*, float*, char*, size_t);

/// The OpenImageIO plugin (image_io_oiio.cpp), loaded once on first use: beside the executable, else at the
/// build-tree path, else through the library search path; NAVE_OIIO_PLUGIN overrides all three.
struct Plugin {
    WriteFn write = nullptr;
    ReadFn read = nullptr;
    Status status;
};

const Plugin& LoadPlugin() {
    static Plugin plugin;
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
            void* handle = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (handle == nullptr) {
                tried += "\n  " + c + ": " + dlerror();
                continue;
            }
            plugin.write = reinterpret_cast<WriteFn>(dlsym(handle, "NaveOiioWrite"));
            plugin.read = reinterpret_cast<ReadFn>(dlsym(handle, "NaveOiioRead"));
            if (plugin.write && plugin.read) return;
            tried += "\n  " + c + ": NaveOiioWrite/NaveOiioRead missing";
        }
        plugin.status = InternalError("cannot load the OpenImageIO plugin libnave_oiio.so (set NAVE_OIIO_PLUGIN); "
                                      "tried:{}", tried);
    });
    return plugin;
}

/// `dir/name.tmp-PID-N.ext`: same directory (rename stays atomic), same extension (OIIO picks the format).
std::filesystem::path TempPathFor(const std::filesystem::path& path) {
    static std::atomic<int> counter{0};
    std::filesystem::path p = path;
    p.replace_filename(path.stem().string() + ".tmp-" + std::to_string(getpid()) + "-" +
                       std::to_string(counter.fetch_add(1)) + path.extension().string());
    return p;
}

/// The one adapter from OpenImageIO's errors to Status: every failure names the file.
Status Write(const std::filesystem::path& path, int width, int height, const std::vector<std::string>& channels,
             const std::vector<int>& formats, bool uint8, const void* data,
             const std::vector<std::pair<std::string, std::string>>& metadata) {
    const Plugin& plugin = LoadPlugin();
    NAVE_RETURN_IF_ERROR(plugin.status);
    std::vector<const char*> names, keys, values;
    for (const auto& c : channels) names.push_back(c.c_str());
    for (const auto& [k, v] : metadata) {
        keys.push_back(k.c_str());
        values.push_back(v.c_str());
    }
    std::filesystem::path temp = TempPathFor(path);
    char err[1024] = {0};
    int rc = plugin.write(path.c_str(), temp.c_str(), width, height, int(channels.size()), names.data(),
                          formats.data(), uint8 ? 1 : 0, data, int(metadata.size()), keys.data(), values.data(),
                          err, sizeof(err));
    std::error_code ec;
    if (rc != 0) {
        std::filesystem::remove(temp, ec);
        return IoError("{}: {}", path.string(), err);
    }
    std::filesystem::rename(temp, path, ec);
    if (ec) {
        std::filesystem::remove(temp, ec);
        return IoError("{}: cannot rename {} into place: {}", path.string(), temp.string(), ec.message());
    }
    return Status::Ok();
}

}  // namespace

Status WriteExr(const std::filesystem::path& path, const FloatImage& image,
                const std::vector<std::pair<std::string, std::string>>& metadata) {
    NAVE_CHECK_EQ(image.pixels.size(), size_t(image.width) * image.height * image.channels.size());
    std::vector<int> formats;
    // Depth needs float's range and precision; colours are fine in half, as EXR viewers expect.
    for (const std::string& c : image.channels) formats.push_back(c == "Z" ? 0 : 1);
    return Write(path, image.width, image.height, image.channels, formats, false, image.pixels.data(), metadata);
}

Status WriteRgb8(const std::filesystem::path& path, int width, int height, const std::vector<uint8_t>& rgb,
                 const std::vector<std::pair<std::string, std::string>>& metadata) {
    NAVE_CHECK_EQ(rgb.size(), size_t(width) * height * 3);
    return Write(path, width, height, {"R", "G", "B"}, {2, 2, 2}, true, rgb.data(), metadata);
}

StatusOr<FloatImage> ReadImage(const std::filesystem::path& path) {
    const Plugin& plugin = LoadPlugin();
    NAVE_RETURN_IF_ERROR(plugin.status);
    FloatImage image;
    int channels = 0;
    char err[1024] = {0};
    if (plugin.read(path.c_str(), &image.width, &image.height, &channels, nullptr, nullptr, err, sizeof(err)) != 0) {
        return IoError("{}: {}", path.string(), err);
    }
    std::vector<char> names(size_t(channels) * 64);
    image.pixels.resize(size_t(image.width) * image.height * channels);
    if (plugin.read(path.c_str(), &image.width, &image.height, &channels, names.data(), image.pixels.data(), err,
                    sizeof(err)) != 0) {
        return IoError("{}: {}", path.string(), err);
    }
    for (int c = 0; c < channels; ++c) image.channels.emplace_back(&names[size_t(c) * 64]);
    return image;
}

}  // namespace nave::render
