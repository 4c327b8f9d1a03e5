#include "render/image_io.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <atomic>
#include <system_error>

namespace nave::render {
namespace {

/// The one adapter from OIIO's error strings to Status.
Status OiioError(const std::filesystem::path& path, const std::string& what, const std::string& detail) {
    std::string d = detail.empty() ? OIIO::geterror() : detail;
    return IoError("{}: {}: {}", path.string(), what, d.empty() ? "(OpenImageIO gave no message)" : d);
}

/// `dir/name.tmp-PID-N.ext`: same directory (rename stays atomic), same extension (OIIO picks the format).
std::filesystem::path TempPathFor(const std::filesystem::path& path) {
    static std::atomic<int> counter{0};
    std::filesystem::path p = path;
    p.replace_filename(path.stem().string() + ".tmp-" + std::to_string(getpid()) + "-" +
                       std::to_string(counter.fetch_add(1)) + path.extension().string());
    return p;
}

Status WriteWithOiio(const std::filesystem::path& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc data_type,
                     const void* data) {
    std::filesystem::path temp = TempPathFor(path);
    {
        auto out = OIIO::ImageOutput::create(path.string());
        if (!out) return OiioError(path, "no writer for this extension", "");
        if (!out->open(temp.string(), spec)) return OiioError(path, "cannot open for writing", out->geterror());
        if (!out->write_image(data_type, data)) {
            std::string e = out->geterror();
            out->close();
            std::error_code ec;
            std::filesystem::remove(temp, ec);
            return OiioError(path, "write failed", e);
        }
        if (!out->close()) return OiioError(path, "close failed", out->geterror());
    }
    std::error_code ec;
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
    OIIO::ImageSpec spec(image.width, image.height, int(image.channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = image.channels;
    spec.channelformats.clear();
    for (const std::string& c : image.channels) {
        // Depth needs float's range and precision; colours are fine in half, as EXR viewers expect.
        spec.channelformats.push_back(c == "Z" ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF);
    }
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    spec.attribute("compression", "zip");
    return WriteWithOiio(path, spec, OIIO::TypeDesc::FLOAT, image.pixels.data());
}

Status WriteRgb8(const std::filesystem::path& path, int width, int height, const std::vector<uint8_t>& rgb,
                 const std::vector<std::pair<std::string, std::string>>& metadata) {
    NAVE_CHECK_EQ(rgb.size(), size_t(width) * height * 3);
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    for (const auto& [k, v] : metadata) spec.attribute(k, v);
    return WriteWithOiio(path, spec, OIIO::TypeDesc::UINT8, rgb.data());
}

StatusOr<FloatImage> ReadImage(const std::filesystem::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return OiioError(path, "cannot open", "");
    const OIIO::ImageSpec& spec = in->spec();
    FloatImage image;
    image.width = spec.width;
    image.height = spec.height;
    image.channels = spec.channelnames;
    image.pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
        return OiioError(path, "read failed", in->geterror());
    }
    in->close();
    return image;
}

}  // namespace nave::render
