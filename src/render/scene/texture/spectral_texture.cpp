#include "src/render/scene/texture/spectral_texture.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <string>

#include "src/imaging/image_io.h"

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
    imaging::FloatImage image;
    image.width = width;
    image.height = height;
    for (int b = 0; b < n; ++b) image.channels.push_back(imaging::BandChannelName(b));
    image.pixels.assign(pixels.begin(), pixels.end());
    return imaging::WriteTiledExr(path, image, 64, {{kBandCentresAttribute, centres}});
}

}  // namespace nave::render
