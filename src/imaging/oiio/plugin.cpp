// nave's OpenImageIO plugin (libnave_oiio.so): the implementation of imaging/oiio_plugin.h. Loaded
// on first use by LoadOiioPlugin; see that header for why OpenImageIO is not linked into `nave`
// itself.

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "src/imaging/image_io.h"
#include "src/imaging/oiio/oiio_status.h"
#include "src/imaging/oiio/oiio_texture_cache.h"
#include "src/imaging/oiio_plugin.h"

namespace nave::imaging::oiio {
namespace {

OIIO::TypeDesc TypeOf(StoredPixel p) {
    switch (p) {
        case StoredPixel::kFloat:
            return OIIO::TypeDesc::FLOAT;
        case StoredPixel::kHalf:
            return OIIO::TypeDesc::HALF;
        case StoredPixel::kUint8:
            return OIIO::TypeDesc::UINT8;
    }
    return OIIO::TypeDesc::FLOAT;
}

/// OIIO's pending global error, or a note that it gave none.
std::string GlobalError() { return OIIO::geterror(); }

class Plugin final : public OiioPlugin {
  public:
    StatusOr<std::vector<unsigned char>> EncodeImage(const std::filesystem::path& path,
                                                     const ImageWriteRequest& r) const override {
        NAVE_CHECK_EQ(r.channels.size(), r.stored.size());
        auto out = OIIO::ImageOutput::create(path.string());
        if (!out) return OiioError(path, "no image writer for this extension", GlobalError());
        if (!out->supports("ioproxy"))
            return IoError(
                "{}: OpenImageIO cannot encode this format in memory; write OpenEXR or "
                "PNG",
                path.string());
        const bool uint8 = !r.stored.empty() && r.stored[0] == StoredPixel::kUint8;
        const OIIO::TypeDesc in_type = uint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
        OIIO::ImageSpec spec(r.width, r.height, int(r.channels.size()), in_type);
        spec.channelnames = r.channels;
        if (!uint8) {
            spec.channelformats.clear();
            for (StoredPixel p : r.stored) spec.channelformats.push_back(TypeOf(p));
            spec.format = TypeOf(r.stored.empty() ? StoredPixel::kFloat : r.stored[0]);
            spec.attribute("compression", "zip");
        }
        if (r.tile_size > 0) {
            spec.tile_width = spec.tile_height = r.tile_size;
            spec.tile_depth = 1;
        }
        for (const auto& [key, value] : r.metadata) spec.attribute(key, value);
        std::vector<unsigned char> bytes;
        OIIO::Filesystem::IOVecOutput proxy(bytes);
        if (!out->set_ioproxy(&proxy) || !out->open(path.string(), spec))
            return IoError("{}: cannot encode: {}", path.string(), out->geterror());
        if (!out->write_image(in_type, r.pixels)) {
            std::string err = out->geterror();
            out->close();
            return IoError("{}: cannot encode: {}", path.string(), err);
        }
        if (!out->close()) return IoError("{}: cannot encode: {}", path.string(), out->geterror());
        return bytes;
    }

    StatusOr<FloatImage> ReadImage(const std::filesystem::path& path) const override {
        auto in = OIIO::ImageInput::open(path.string());
        if (!in) return OiioError(path, "cannot open image", GlobalError());
        const OIIO::ImageSpec& spec = in->spec();
        FloatImage image;
        image.width = spec.width;
        image.height = spec.height;
        image.channels = spec.channelnames;
        image.pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
        if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
            return OiioError(path, "cannot read image", in->geterror());
        in->close();
        return image;
    }

    StatusOr<std::unique_ptr<TextureCache>> CreateTextureCache(
        size_t max_memory_bytes) const override {
        return CreateOiioTextureCache(max_memory_bytes);
    }

    Status MakeTexture(const std::filesystem::path& source, const std::filesystem::path& output,
                       TextureContent content) const override {
        std::error_code ec;
        if (!std::filesystem::exists(source, ec))
            return NotFoundError("{}: no such file", source.string());
        OIIO::ImageBuf in(source.string());
        if (!in.read(0, 0, /*force=*/true, OIIO::TypeFloat)) {
            Status st = OiioError(source, "unreadable", in.geterror());
            return InvalidArgumentError("{}", st.message());
        }
        // make_texture stamps the output with the current time unless given a DateTime. The
        // converted file is a function of the source's bytes (its name carries their checksum), so
        // it carries the DateTime written in the source, or an empty one (read back as none): not
        // the time of conversion, nor the source's modification time, which changes when the same
        // bytes are written again (as the abbey's generated textures are on every run).
        const std::string source_date = in.spec().get_string_attribute("DateTime");
        const bool colour = content == TextureContent::kColour;
        if (colour) {
            // Colour textures are sRGB-encoded (IEC 61966-2-1); the renderer filters and lifts
            // linear values. Alpha and further channels are linear already, and colorconvert leaves
            // alpha alone.
            OIIO::ImageBuf linear;
            if (!OIIO::ImageBufAlgo::colorconvert(linear, in, "sRGB", "linear")) {
                Status st =
                    OiioError(source, "cannot convert from sRGB to linear", linear.geterror());
                return InvalidArgumentError("{}", st.message());
            }
            in = std::move(linear);
        }
        OIIO::ImageSpec config;
        // Colour: half floats (OpenEXR; OIIO's TIFF writer would store half as float); data: the
        // source's pixel type. Both tiled and MIP-mapped by make_texture.
        config.format = colour ? OIIO::TypeHalf : in.nativespec().format;
        config.tile_width = config.tile_height = 64;
        config.attribute("wrapmodes", "periodic,periodic");
        config.attribute("compression", "zip");
        config.attribute("DateTime", source_date);
        // Its average colour is a sum that OIIO reduces over threads in the order they finish,
        // which can change its last digits from run to run; nave does not read it.
        config.attribute("maketx:compute_average", 0);
        NAVE_RETURN_IF_ERROR(CheckRoomFor(output, source, MostBytesOfTexture(in.spec(), config)));
        if (!OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, in,
                                              output.string(), config))
            return IoError("{}: cannot write the texture converted from {}: {}", output.string(),
                           source.string(), GlobalError());
        return CheckWrittenToTheEnd(output, source);
    }

  private:
    /// The most bytes a tiled, MIP-mapped texture of `source`'s size can take on disk in
    /// `config`'s pixel type: every level uncompressed (zip keeps a tile raw when compressing
    /// would grow it, in OpenEXR as in TIFF), each tile's header and offset, and a MiB for the
    /// file's header.
    static uint64_t MostBytesOfTexture(const OIIO::ImageSpec& source,
                                       const OIIO::ImageSpec& config) {
        const uint64_t pixel_bytes = uint64_t(source.nchannels) * config.format.size();
        const uint64_t tile = uint64_t(config.tile_width);
        uint64_t bytes = uint64_t(1) << 20;
        uint64_t w = uint64_t(std::max(source.width, 1)), h = uint64_t(std::max(source.height, 1));
        for (;;) {
            const uint64_t tiles = ((w + tile - 1) / tile) * ((h + tile - 1) / tile);
            bytes += w * h * pixel_bytes + tiles * 64;
            if (w == 1 && h == 1) break;
            w = std::max<uint64_t>(w / 2, 1);
            h = std::max<uint64_t>(h / 2, 1);
        }
        return bytes;
    }

    /// Refuses to start a texture the disk has no room for. OpenEXR 3.1's tiled writer does not
    /// come back from a full disk: a tile whose write failed keeps its buffer taken, and the next
    /// row of tiles OpenImageIO writes waits for that buffer forever (seen in the full-disk
    /// trials as a preprocess that never ended). So the room is taken first, with fallocate on
    /// the output's own (temporary) name, and given back before make_texture writes: preprocess
    /// converts textures one at a time while nothing else of it writes.
    static Status CheckRoomFor(const std::filesystem::path& output,
                               const std::filesystem::path& source, uint64_t bytes) {
        const int fd = ::open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0)
            return IoError("{}: cannot create the texture converted from {}: {}", output.string(),
                           source.string(), std::strerror(errno));
        const int reserved = ::posix_fallocate(fd, 0, off_t(bytes));
        const bool emptied = ::ftruncate(fd, 0) == 0;
        ::close(fd);
        if (reserved == ENOSPC || reserved == EDQUOT)
            return IoError(
                "{}: no room on the disk for the texture converted from {}: it may take up to {} "
                "bytes",
                output.string(), source.string(), bytes);
        // Other refusals (a file system without fallocate) leave the check to the write itself.
        if (!emptied)
            return IoError("{}: cannot empty the room set aside for the texture converted from {}",
                           output.string(), source.string());
        return Status::Ok();
    }

    /// make_texture writes through a buffered file whose last flush fails silently on a full disk:
    /// a texture cut short would pass for converted. Its levels are written largest first, so the
    /// smallest, read back whole, is at the end of the file.
    static Status CheckWrittenToTheEnd(const std::filesystem::path& output,
                                       const std::filesystem::path& source) {
        auto in = OIIO::ImageInput::open(output.string());
        if (!in)
            return IoError(
                "{}: the texture converted from {} cannot be read back (is the disk "
                "full?): {}",
                output.string(), source.string(), GlobalError());
        int level = 0;
        while (in->seek_subimage(0, level + 1)) ++level;
        const OIIO::ImageSpec spec = in->spec(0, level);
        std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) *
                                  size_t(spec.nchannels));
        const bool read =
            in->read_image(0, level, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
        const std::string error = read ? std::string() : in->geterror();
        in->close();
        if (!read)
            return IoError(
                "{}: the texture converted from {} is incomplete on disk (is the disk "
                "full?): {}",
                output.string(), source.string(), error);
        return Status::Ok();
    }
};

}  // namespace
}  // namespace nave::imaging::oiio

extern "C" __attribute__((visibility("default"))) nave::imaging::OiioPlugin* NaveCreateOiioPlugin(
    int version) {
    if (version != nave::imaging::kOiioPluginVersion) return nullptr;
    // OpenEXR 3.1's writers wait forever on their thread pool when a write fails (a full disk)
    // while worker threads compress: seen as a texture conversion that never returned in the
    // full-disk trials. Every EXR nave writes (textures, images) goes through here, so the pool is
    // turned off once, for all of them (-1: OpenImageIO's "exr_threads" without threads).
    OIIO::attribute("exr_threads", -1);
    return new nave::imaging::oiio::Plugin();
}
