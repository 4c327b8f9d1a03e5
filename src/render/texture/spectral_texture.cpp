#include "render/texture/spectral_texture.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <string>

#include "render/texture/oiio_status.h"

namespace nave::render {

namespace {

StatusOr<std::vector<float>> ParseBandCentres(const std::filesystem::path& path,
                                              const std::string& text) {
    std::vector<float> out;
    size_t pos = 0;
    while (pos <= text.size()) {
        size_t end = text.find(',', pos);
        if (end == std::string::npos) end = text.size();
        std::string field = text.substr(pos, end - pos);
        field.erase(0, field.find_first_not_of(" \t"));
        field.erase(field.find_last_not_of(" \t") + 1);
        float v = 0.f;
        auto [p, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
        if (field.empty() || ec != std::errc() || p != field.data() + field.size())
            return InvalidArgumentError(
                "{}: {} entry {}: expected a wavelength in nm, found \"{}\"", path.string(),
                kBandCentresAttribute, out.size(), field);
        if (!(v > 0.f && v < 10000.f))
            return InvalidArgumentError(
                "{}: {} entry {}: expected a wavelength in (0, 10000) nm, "
                "found {}",
                path.string(), kBandCentresAttribute, out.size(), v);
        if (!out.empty() && !(v > out.back()))
            return InvalidArgumentError(
                "{}: {} entry {}: expected more than {} nm (increasing), "
                "found {}",
                path.string(), kBandCentresAttribute, out.size(), out.back(), v);
        out.push_back(v);
        pos = end + 1;
    }
    return out;
}

}  // namespace

float InterpolateBands(std::span<const float> centres_nm, std::span<const float> values,
                       float lambda_nm) {
    size_t n = std::min(centres_nm.size(), values.size());
    if (n == 0) return 0.f;
    if (lambda_nm <= centres_nm[0]) return values[0];
    if (lambda_nm >= centres_nm[n - 1]) return values[n - 1];
    size_t i = size_t(std::upper_bound(centres_nm.begin(), centres_nm.begin() + n, lambda_nm) -
                      centres_nm.begin());
    float t = (lambda_nm - centres_nm[i - 1]) / (centres_nm[i] - centres_nm[i - 1]);
    return values[i - 1] + t * (values[i] - values[i - 1]);
}

StatusOr<SpectralTexture> SpectralTexture::Open(TextureCache& cache,
                                                const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(TextureRef ref, cache.Open(path));
    StatusOr<std::string> attr = cache.StringAttribute(ref, kBandCentresAttribute);
    if (!attr.ok())
        return InvalidArgumentError(
            "{}: not a spectral texture: expected the header attribute "
            "\"{}\" (band centres in nm), found none",
            path.string(), kBandCentresAttribute);
    NAVE_ASSIGN_OR_RETURN(std::vector<float> bands, ParseBandCentres(path, *attr));
    int channels = cache.info(ref).channels;
    if (int(bands.size()) != channels)
        return InvalidArgumentError(
            "{}: expected one band centre per channel ({} channels), found "
            "{} in \"{}\"",
            path.string(), channels, bands.size(), kBandCentresAttribute);
    if (channels > kMaxSpectralBands)
        return InvalidArgumentError("{}: expected at most {} bands, found {}", path.string(),
                                    kMaxSpectralBands, channels);
    SpectralTexture tex;
    tex.cache_ = &cache;
    tex.ref_ = ref;
    tex.band_centres_nm_ = std::move(bands);
    return tex;
}

StatusOr<SampledSpectrum> SpectralTexture::Sample(float s, float t,
                                                  const TextureFootprint& footprint,
                                                  const SampledWavelengths& lambda) const {
    std::array<float, kMaxSpectralBands> values{};
    int n = int(band_centres_nm_.size());
    NAVE_RETURN_IF_ERROR(cache_->Lookup(ref_, s, t, footprint, 0, n, values.data()));
    SampledSpectrum out;
    for (int i = 0; i < kNumWavelengths; ++i)
        out[i] = InterpolateBands(band_centres_nm_, std::span<const float>(values.data(), n),
                                  lambda.lambda_nm(i));
    return out;
}

Status WriteSpectralTexture(const std::filesystem::path& path, int width, int height,
                            std::span<const float> band_centres_nm, std::span<const float> pixels) {
    int n = int(band_centres_nm.size());
    if (n == 0 || n > kMaxSpectralBands)
        return InvalidArgumentError("{}: expected 1 to {} bands, found {}", path.string(),
                                    kMaxSpectralBands, n);
    if (pixels.size() != size_t(width) * size_t(height) * size_t(n))
        return InvalidArgumentError("{}: expected {} x {} x {} values, found {}", path.string(),
                                    width, height, n, pixels.size());
    std::string centres;
    for (int b = 0; b < n; ++b) {
        if (b > 0) centres += ',';
        centres += std::to_string(band_centres_nm[b]);
    }
    // OIIO picks the format from the extension, so the temporary name keeps ".exr" last.
    static std::atomic<int> counter{0};
    std::filesystem::path temp = path;
    temp.replace_filename(path.stem().string() + ".tmp-" + std::to_string(getpid()) + "-" +
                          std::to_string(counter++) + ".exr");
    auto out = OIIO::ImageOutput::create(temp.string());
    if (!out)
        return texture_internal::OiioError(temp, "cannot create an OpenEXR writer",
                                           OIIO::geterror());
    OIIO::ImageSpec spec(width, height, n, OIIO::TypeHalf);
    spec.tile_width = 64;
    spec.tile_height = 64;
    spec.channelnames.clear();
    for (int b = 0; b < n; ++b) spec.channelnames.push_back("band" + std::to_string(b));
    spec.attribute(kBandCentresAttribute, centres);
    spec.attribute("compression", "zip");
    bool ok = out->open(temp.string(), spec) && out->write_image(OIIO::TypeFloat, pixels.data()) &&
              out->close();
    if (!ok) {
        std::string err = out->geterror();
        std::error_code ec;
        std::filesystem::remove(temp, ec);
        return IoError("{}: cannot write spectral texture: {}", path.string(), err);
    }
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec)
        return IoError("{}: cannot rename from {}: {}", path.string(), temp.string(), ec.message());
    return Status();
}

}  // namespace nave::render
