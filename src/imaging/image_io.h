#pragma once
// Reading and writing images through OpenImageIO (in nave's plugin, imaging/oiio_plugin.h). Every
// OIIO error comes back as a Status naming the file. Images are encoded in memory and written by
// nave (core/file.h's AtomicFile): under a temporary name in the target's directory, synced, and
// renamed when complete, so an interrupted write or a full disk never leaves a half-written image
// under the real name.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "src/core/status.h"

namespace nave::imaging {

/// A float image with named channels, interleaved (pixel-major), top row first.
struct FloatImage {
    int width = 0, height = 0;
    std::vector<std::string> channels;  ///< "R", "G", "B", "albedo.R", "Z"...
    std::vector<float> pixels;          ///< width * height * channels.size()
};

using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

/// The header attribute of a spectral texture (one channel per wavelength band) holding the band
/// centres, comma-separated, in nm, strictly increasing ("400,420,440").
inline constexpr char kBandCentresAttribute[] = "nave:band_centres_nm";
/// The channel name of band `b` of a spectral texture: "band00", "band01"... OpenEXR stores
/// channels sorted by name, so the names are zero-padded to keep the file's channel order the band
/// order (at most 100 bands).
std::string BandChannelName(int b);

/// Writes a linear float OpenEXR file (half float for colour, float for depth "Z") with string
/// metadata.
Status WriteExr(const std::filesystem::path& path, const FloatImage& image,
                const ImageMetadata& metadata);
/// Writes a tiled (tile_size x tile_size), half-float OpenEXR file, as textures are read best. The
/// bytes depend only on the image and the metadata: no time of writing (the DateTime is empty
/// unless `metadata` has one).
Status WriteTiledExr(const std::filesystem::path& path, const FloatImage& image, int tile_size,
                     const ImageMetadata& metadata);
/// Writes an 8-bit RGB image (PNG or anything OIIO knows by extension); `rgb` is width * height * 3
/// bytes.
Status WriteRgb8(const std::filesystem::path& path, int width, int height,
                 const std::vector<uint8_t>& rgb, const ImageMetadata& metadata);
/// Reads an image's first subimage as floats.
StatusOr<FloatImage> ReadImage(const std::filesystem::path& path);

/// An image encoded in memory (its file's bytes), to be written to `path`.
struct EncodedImage {
    std::filesystem::path path;
    std::vector<unsigned char> bytes;
};
/// WriteExr's file, in memory.
StatusOr<EncodedImage> EncodeExr(const std::filesystem::path& path, const FloatImage& image,
                                 const ImageMetadata& metadata);
/// WriteRgb8's file, in memory.
StatusOr<EncodedImage> EncodeRgb8(const std::filesystem::path& path, int width, int height,
                                  const std::vector<uint8_t>& rgb, const ImageMetadata& metadata);
/// Writes images as a set: each under `<path>.tmp-<pid>-<n>` (AtomicFile), all synced before any
/// is renamed into place. A failure (a full disk) is an IoError naming the file; every file that
/// was there before is left as it was, and no temporary stays.
Status WriteImages(std::span<const EncodedImage> images);

}  // namespace nave::imaging
