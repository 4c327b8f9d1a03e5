#include "src/imaging/image_io.h"

#include <algorithm>

#include "src/core/file.h"
#include "src/imaging/oiio_plugin.h"

namespace nave::imaging {
namespace {

StatusOr<EncodedImage> Encode(const std::filesystem::path& path, const ImageWriteRequest& request) {
    NAVE_ASSIGN_OR_RETURN(const OiioPlugin* plugin, LoadOiioPlugin());
    NAVE_ASSIGN_OR_RETURN(std::vector<unsigned char> bytes, plugin->EncodeImage(path, request));
    return EncodedImage{path, std::move(bytes)};
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

Status WriteImages(std::span<const EncodedImage> images) {
    // All written and synced under temporary names before the first rename: a full disk shows as
    // a failed write or sync, and then every file that was there before stays as it was.
    std::vector<AtomicFile> files;
    files.reserve(images.size());
    for (const EncodedImage& image : images) {
        NAVE_ASSIGN_OR_RETURN(AtomicFile file, AtomicFile::Create(image.path));
        NAVE_RETURN_IF_ERROR(file.Write(image.bytes.data(), image.bytes.size()));
        NAVE_RETURN_IF_ERROR(file.Sync());
        files.push_back(std::move(file));
    }
    for (AtomicFile& file : files) NAVE_RETURN_IF_ERROR(file.Commit());
    return Status::Ok();
}

StatusOr<EncodedImage> EncodeExr(const std::filesystem::path& path, const FloatImage& image,
                                 const ImageMetadata& metadata) {
    ImageWriteRequest request = FloatRequest(image, metadata);
    // Depth needs float's range and precision; colours are fine in half, as EXR viewers expect.
    for (const std::string& c : image.channels)
        request.stored.push_back(c == "Z" ? StoredPixel::kFloat : StoredPixel::kHalf);
    return Encode(path, request);
}

StatusOr<EncodedImage> EncodeRgb8(const std::filesystem::path& path, int width, int height,
                                  const std::vector<uint8_t>& rgb, const ImageMetadata& metadata) {
    NAVE_CHECK_EQ(rgb.size(), size_t(width) * height * 3);
    ImageWriteRequest request;
    request.width = width;
    request.height = height;
    request.channels = {"R", "G", "B"};
    request.stored.assign(3, StoredPixel::kUint8);
    request.pixels = rgb.data();
    request.metadata = metadata;
    return Encode(path, request);
}

Status WriteExr(const std::filesystem::path& path, const FloatImage& image,
                const ImageMetadata& metadata) {
    NAVE_ASSIGN_OR_RETURN(const EncodedImage encoded, EncodeExr(path, image, metadata));
    return WriteImages({&encoded, 1});
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
    NAVE_ASSIGN_OR_RETURN(const EncodedImage encoded, Encode(path, request));
    return WriteImages({&encoded, 1});
}

Status WriteRgb8(const std::filesystem::path& path, int width, int height,
                 const std::vector<uint8_t>& rgb, const ImageMetadata& metadata) {
    NAVE_ASSIGN_OR_RETURN(const EncodedImage encoded,
                          EncodeRgb8(path, width, height, rgb, metadata));
    return WriteImages({&encoded, 1});
}

StatusOr<FloatImage> ReadImage(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(const OiioPlugin* plugin, LoadOiioPlugin());
    return plugin->ReadImage(path);
}

}  // namespace nave::imaging
