#include "src/imaging/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <system_error>

#include "src/imaging/oiio_plugin.h"

namespace nave::imaging {
namespace {

/// Writes through the plugin to a temporary name, then renames into place; the temporary file never
/// outlives a failure.
Status WriteAtomically(const std::filesystem::path& path, const ImageWriteRequest& request) {
    NAVE_ASSIGN_OR_RETURN(const OiioPlugin* plugin, LoadOiioPlugin());
    const std::filesystem::path temp = TemporaryImagePath(path);
    std::error_code ec;
    if (Status st = plugin->WriteImage(path, temp, request); !st.ok()) {
        std::filesystem::remove(temp, ec);
        return st;
    }
    std::filesystem::rename(temp, path, ec);
    if (ec) {
        std::filesystem::remove(temp, ec);
        return IoError("{}: cannot rename {} into place: {}", path.string(), temp.string(),
                       ec.message());
    }
    return Status::Ok();
}

ImageWriteRequest FloatRequest(const FloatImage& image, const ImageMetadata& metadata) {
    NAVE_CHECK_EQ(image.pixels.size(), size_t(image.width) * image.height * image.channels.size());
    ImageWriteRequest request;
    request.width = image.width;
    request.height = image.height;
    request.channels = image.channels;
    request.pixels = image.pixels.data();
    request.metadata = metadata;
    return request;
}

}  // namespace

std::string BandChannelName(int b) {
    NAVE_CHECK(b >= 0 && b < 100) << "band " << b;
    return fmt::format("band{:02d}", b);
}

std::filesystem::path TemporaryImagePath(const std::filesystem::path& path) {
    static std::atomic<int> counter{0};
    std::filesystem::path p = path;
    p.replace_filename(path.stem().string() + ".tmp-" + std::to_string(getpid()) + "-" +
                       std::to_string(counter.fetch_add(1)) + path.extension().string());
    return p;
}

Status WriteExr(const std::filesystem::path& path, const FloatImage& image,
                const ImageMetadata& metadata) {
    ImageWriteRequest request = FloatRequest(image, metadata);
    // Depth needs float's range and precision; colours are fine in half, as EXR viewers expect.
    for (const std::string& c : image.channels)
        request.stored.push_back(c == "Z" ? StoredPixel::kFloat : StoredPixel::kHalf);
    return WriteAtomically(path, request);
}

Status WriteTiledExr(const std::filesystem::path& path, const FloatImage& image, int tile_size,
                     const ImageMetadata& metadata) {
    ImageWriteRequest request = FloatRequest(image, metadata);
    // OIIO's OpenEXR writer stamps the current time as DateTime when given none. A texture is a
    // function of its pixels and metadata (writing the same one twice gives the same bytes, and the
    // texture converted from it is named after those bytes), so it gets an empty DateTime, which
    // OIIO reads back as none, unless the caller names one.
    const bool dated = std::any_of(metadata.begin(), metadata.end(),
                                   [](const auto& entry) { return entry.first == "DateTime"; });
    if (!dated) request.metadata.emplace_back("DateTime", "");
    request.stored.assign(image.channels.size(), StoredPixel::kHalf);
    request.tile_size = tile_size;
    return WriteAtomically(path, request);
}

Status WriteRgb8(const std::filesystem::path& path, int width, int height,
                 const std::vector<uint8_t>& rgb, const ImageMetadata& metadata) {
    NAVE_CHECK_EQ(rgb.size(), size_t(width) * height * 3);
    ImageWriteRequest request;
    request.width = width;
    request.height = height;
    request.channels = {"R", "G", "B"};
    request.stored.assign(3, StoredPixel::kUint8);
    request.pixels = rgb.data();
    request.metadata = metadata;
    return WriteAtomically(path, request);
}

StatusOr<FloatImage> ReadImage(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(const OiioPlugin* plugin, LoadOiioPlugin());
    return plugin->ReadImage(path);
}

}  // namespace nave::imaging
