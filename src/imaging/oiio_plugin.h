#pragma once
// The interface of nave's OpenImageIO plugin (libnave_oiio.so, built from src/imaging/oiio/).
// Debian's OpenImageIO pulls in some 250 shared libraries whose loading alone costs ~130 MB of
// resident memory; linked into `nave`, that cost would hit every command, including `nave
// preprocess --memory 64M` on a model without textures. So everything that needs OpenImageIO (image
// files, the texture cache, texture conversion) lives in the plugin, loaded on first use, and the
// rest of nave reaches it only through this interface.
//
// The plugin is built by the same build as the executable, with the same compiler and the same
// nave_core, so C++ types (Status, std::string, std::unique_ptr) cross the boundary;
// kOiioPluginVersion guards against a stale plugin from another build left beside the executable.

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "src/core/status.h"

namespace nave::imaging {

class TextureCache;
struct FloatImage;

/// Bumped whenever OiioPlugin's methods or the types they take change.
inline constexpr int kOiioPluginVersion = 4;

/// The pixel type a channel is stored as in the file.
enum class StoredPixel { kFloat, kHalf, kUint8 };

/// Everything needed to write one image.
struct ImageWriteRequest {
    int width = 0, height = 0;
    std::vector<std::string> channels;
    std::vector<StoredPixel> stored;  ///< one per channel; all kUint8 or none
    const void* pixels = nullptr;  ///< interleaved, top row first: floats, or bytes when all kUint8
    int tile_size = 0;             ///< 0: scanlines; else square tiles of this size
    std::vector<std::pair<std::string, std::string>> metadata;
};

/// What a texture conversion keeps: colours are decoded from sRGB to linear and stored in half
/// floats, so that MIP levels average light rather than encoded values; data (alpha, normals,
/// roughness) keeps its values and pixel type.
enum class TextureContent { kColour, kData };

/// The OpenImageIO side. Every method is thread-safe; every failure is a Status naming the file.
class OiioPlugin {
  public:
    virtual ~OiioPlugin() = default;

    /// The bytes of `request` encoded in the format `path`'s extension names, in memory: the
    /// caller writes them (OpenImageIO's file writers do not report a write that fails when their
    /// last buffer is flushed, so a full disk could leave a truncated image behind an exit code 0).
    virtual StatusOr<std::vector<unsigned char>> EncodeImage(
        const std::filesystem::path& path, const ImageWriteRequest& request) const = 0;
    /// Reads the first subimage as floats.
    virtual StatusOr<FloatImage> ReadImage(const std::filesystem::path& path) const = 0;
    /// A texture cache of its own whose tiles use at most `max_memory_bytes`.
    virtual StatusOr<std::unique_ptr<TextureCache>> CreateTextureCache(
        size_t max_memory_bytes) const = 0;
    /// Converts `source` into a tiled (64x64), MIP-mapped texture at `output` (format by
    /// extension). A missing source is NotFound, an unreadable one InvalidArgument; a failure to
    /// write `output` is IoError.
    virtual Status MakeTexture(const std::filesystem::path& source,
                               const std::filesystem::path& output,
                               TextureContent content) const = 0;
};

/// The plugin, loaded once on first call: NAVE_OIIO_PLUGIN if set, else libnave_oiio.so beside the
/// executable, else at the build tree's path, else through the library search path. An error lists
/// every place tried and why each failed. Thread-safe.
StatusOr<const OiioPlugin*> LoadOiioPlugin();

}  // namespace nave::imaging

/// The plugin's one exported symbol: a new OiioPlugin if `version` is the plugin's
/// kOiioPluginVersion, else null. Owned by the caller.
extern "C" nave::imaging::OiioPlugin* NaveCreateOiioPlugin(int version);
