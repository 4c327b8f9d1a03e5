#pragma once
// Writing images through OpenImageIO. Every OIIO error comes back through one adapter as a Status naming the
// file. Files are written under a temporary name in the target's directory and renamed when complete, so an
// interrupted render never leaves a half-written image under the real name.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/status.h"

namespace nave::render {

/// A float image with named channels, interleaved (pixel-major), top row first.
struct FloatImage {
    int width = 0, height = 0;
    std::vector<std::string> channels;  ///< "R", "G", "B", "albedo.R", "Z"...
    std::vector<float> pixels;          ///< width * height * channels.size()
};

/// Writes a linear float OpenEXR file (half float for colour, float for depth) with string metadata.
Status WriteExr(const std::filesystem::path& path, const FloatImage& image,
                const std::vector<std::pair<std::string, std::string>>& metadata);
/// Writes an 8-bit RGB image (PNG or anything OIIO knows by extension); `rgb` is width * height * 3 bytes.
Status WriteRgb8(const std::filesystem::path& path, int width, int height, const std::vector<uint8_t>& rgb,
                 const std::vector<std::pair<std::string, std::string>>& metadata);
/// Reads an image as float RGB(A...) (tests, comparisons).
StatusOr<FloatImage> ReadImage(const std::filesystem::path& path);

}  // namespace nave::render
