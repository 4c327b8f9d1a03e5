// The OpenImageIO side of image_io.h, built as a plugin (libnave_oiio.so) that image_io.cpp loads on first
// use. Debian's OpenImageIO pulls in some 250 shared libraries whose loading alone costs ~130 MB of resident
// memory; linked into `nave` that cost would hit every command, including `nave preprocess --memory 64M`.
// The interface is plain C so that no C++ ABI crosses the dlopen boundary.

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

void SetError(char* err, size_t err_size, const std::string& message) {
    if (err_size == 0) return;
    std::snprintf(err, err_size, "%s", message.c_str());
}

std::string OiioMessage(const std::string& detail) {
    std::string d = detail.empty() ? OIIO::geterror() : detail;
    return d.empty() ? "(OpenImageIO gave no message)" : d;
}

}  // namespace

extern "C" {

/// Writes `pixels` (width * height * channel_count floats, interleaved) to `temp_path`, choosing the format by
/// the extension of `format_path`. `channel_formats[c]`: 0 float, 1 half, 2 uint8. Returns 0 on success, else
/// writes a message into `err`.
int NaveOiioWrite(const char* format_path, const char* temp_path, int width, int height, int channel_count,
                  const char* const* channel_names, const int* channel_formats, int data_is_uint8,
                  const void* pixels, int metadata_count, const char* const* keys, const char* const* values,
                  char* err, size_t err_size) {
    auto out = OIIO::ImageOutput::create(format_path);
    if (!out) {
        SetError(err, err_size, "no writer for this extension: " + OiioMessage(""));
        return 1;
    }
    OIIO::ImageSpec spec(width, height, channel_count, data_is_uint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    spec.channelnames.assign(channel_names, channel_names + channel_count);
    if (!data_is_uint8) {
        spec.channelformats.clear();
        for (int c = 0; c < channel_count; ++c) {
            spec.channelformats.push_back(channel_formats[c] == 1 ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
        }
        spec.attribute("compression", "zip");
    }
    for (int i = 0; i < metadata_count; ++i) spec.attribute(keys[i], values[i]);
    if (!out->open(temp_path, spec)) {
        SetError(err, err_size, "cannot open for writing: " + OiioMessage(out->geterror()));
        return 1;
    }
    if (!out->write_image(data_is_uint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT, pixels)) {
        SetError(err, err_size, "write failed: " + OiioMessage(out->geterror()));
        out->close();
        return 1;
    }
    if (!out->close()) {
        SetError(err, err_size, "close failed: " + OiioMessage(out->geterror()));
        return 1;
    }
    return 0;
}

/// Reads an image as floats. Call with pixels == nullptr to get the size (width, height, channels); then
/// with a buffer of width * height * channels floats and `names` of channels * 64 chars.
int NaveOiioRead(const char* path, int* width, int* height, int* channel_count, char* names, float* pixels,
                 char* err, size_t err_size) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        SetError(err, err_size, "cannot open: " + OiioMessage(""));
        return 1;
    }
    const OIIO::ImageSpec& spec = in->spec();
    *width = spec.width;
    *height = spec.height;
    *channel_count = spec.nchannels;
    if (pixels != nullptr) {
        for (int c = 0; c < spec.nchannels; ++c) {
            std::snprintf(names + 64 * c, 64, "%s", spec.channelnames[size_t(c)].c_str());
        }
        if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels)) {
            SetError(err, err_size, "read failed: " + OiioMessage(in->geterror()));
            return 1;
        }
    }
    in->close();
    return 0;
}

}  // extern "C"
