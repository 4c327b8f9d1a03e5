#pragma once
// Spectral textures: multi-channel images with one channel per wavelength band (e.g. measured
// stained-glass transmittance), the band centres in the header attribute "nave:band_centres_nm"
// ("400,430,460,..." in nm, strictly increasing, one per channel). Sampled at a path's wavelengths
// by linear interpolation between neighbouring bands; outside the first and last band centre the
// end values are held (as Spectrum::FromPiecewiseLinear does for measured tables).

#include <filesystem>
#include <span>
#include <vector>

#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/imaging/image_io.h"
#include "src/imaging/texture_cache.h"

namespace nave::render {

using imaging::TextureCache;
using imaging::TextureFootprint;
using imaging::TextureRef;

using imaging::kBandCentresAttribute;
/// At most this many bands per spectral texture.
inline constexpr int kMaxSpectralBands = 64;

/// A spectral texture opened in a TextureCache. Cheap to copy; valid as long as the cache.
class SpectralTexture {
  public:
    /// Opens `path` and checks its band centres: missing, unparsable, not increasing, outside
    /// (0, 10000) nm, or not one per channel is InvalidArgument naming the file, expected and
    /// found.
    static StatusOr<SpectralTexture> Open(TextureCache& cache, const std::filesystem::path& path);

    /// The texture's values at the path's wavelengths, filtered over `footprint` at (s, t) (the
    /// TextureCache::Lookup convention).
    StatusOr<SampledSpectrum> Sample(float s, float t, const TextureFootprint& footprint,
                                     const SampledWavelengths& lambda) const;

    const std::vector<float>& band_centres_nm() const { return band_centres_nm_; }

  private:
    const TextureCache* cache_ = nullptr;
    TextureRef ref_;
    std::vector<float> band_centres_nm_;
};

/// Interpolates band values at `lambda_nm` (linear between centres, ends held).
float InterpolateBands(std::span<const float> centres_nm, std::span<const float> values,
                       float lambda_nm);

/// Writes a tiled (64x64), half-float OpenEXR spectral texture: `pixels` holds width x height x
/// band_centres_nm.size() values, row by row from the top, bands fastest. Written to a temporary
/// name and renamed. Errors name the file.
Status WriteSpectralTexture(const std::filesystem::path& path, int width, int height,
                            std::span<const float> band_centres_nm, std::span<const float> pixels);

}  // namespace nave::render
