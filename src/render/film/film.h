#pragma once
// The film: per-pixel sums of spectral samples converted to CIE XYZ, taking concurrent adds from
// every worker. Sums are doubles updated atomically, so the order in which bricks and threads add
// their samples changes a pixel only by double rounding (relative ~1e-15 per add), far below the
// float of the output.

#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "src/core/byte_stream.h"
#include "src/core/color.h"
#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/scene/scene_config.h"

namespace nave::render {

/// The 8-bit sRGB display image of linear sRGB pixels `rgb` (3 per pixel, in the film's units: a
/// constant radiance of 1 W m⁻² sr⁻¹ nm⁻¹ has luminance 1) under `output`'s exposure and tone
/// curve.
std::vector<uint8_t> DisplayImage(const std::vector<float>& rgb, const OutputConfig& output);

class Film {
  public:
    Film(int width, int height, const OutputConfig& output);

    /// Bytes a film of width x height holds: 5 doubles of XYZ and the halves' luminance, 7 floats
    /// of AOVs and a counter per pixel, plus what Write converts them into (linear RGB and AOVs in
    /// float, 8-bit PNG).
    static uint64_t MemoryBytes(int width, int height) {
        return uint64_t(width) * uint64_t(height) * ((5 * 8 + 7 * 4 + 4) + (3 + 10) * 4 + 3);
    }

    int width() const { return width_; }
    int height() const { return height_; }
    size_t pixel_count() const { return size_t(width_) * height_; }

    /// Adds radiance `L` carried at `lambda` to pixel `pixel` (y * width + x), from a sample of
    /// half `half` of the render's samples (0 or 1, SampleHalf; kNoHalf for an estimate of the
    /// whole render). The halves give the render's own noise estimate (NoiseEstimate).
    /// Thread-safe, lock-free.
    void AddSample(uint32_t pixel, const SampledSpectrum& L, const SampledWavelengths& lambda,
                   int half) {
        AddXYZ(pixel, SampledToXYZ(L, lambda), half);
    }
    void AddXYZ(uint32_t pixel, const Vec3d& xyz, int half);
    static constexpr int kNoHalf = -1;
    /// The half of the render's samples that sample (path mode: pass; photon mode: iteration)
    /// `index` belongs to: even ones to 0, odd ones to 1.
    static int SampleHalf(uint32_t index) { return int(index & 1u); }
    /// Adds to the auxiliary buffers (first-hit albedo, shading normal, depth). Thread-safe.
    void AddAov(uint32_t pixel, const Vec3f& albedo, const Vec3f& normal, float depth);

    /// The sum of XYZ added to `pixel`.
    Vec3d SumXYZ(uint32_t pixel) const;
    /// The mean luminance (CIE Y) of `pixel`'s samples of half `half` (0 or 1) when `samples`
    /// samples per pixel have been added: half 0 holds ceil(samples / 2) of them, half 1
    /// floor(samples / 2). NaN when that half has none.
    double HalfLuminance(uint32_t pixel, int half, int samples) const {
        const int n = half == 0 ? (samples + 1) / 2 : samples / 2;
        if (n <= 0) return std::nan("");
        return y_half_[2 * size_t(pixel) + size_t(half)].load(std::memory_order_relaxed) / n;
    }
    /// Divides every sum by `samples_per_pixel` for output.
    void SetSamplesPerPixel(double spp) { spp_ = spp; }
    double samples_per_pixel() const { return spp_; }
    /// The estimate of `pixel` in XYZ: sum / spp.
    Vec3d PixelXYZ(uint32_t pixel) const { return SumXYZ(pixel) * (1.0 / spp_); }

    /// Writes linear RGB (plus AOV channels) as EXR with `metadata`, and a tone-mapped sRGB PNG
    /// beside it (DisplayPathOf), as one set: both or neither (imaging::WriteImages).
    Status Write(const std::filesystem::path& exr_path,
                 const std::vector<std::pair<std::string, std::string>>& metadata) const;
    /// The PNG that Write puts beside the EXR `exr_path`: the same name, .png.
    static std::filesystem::path DisplayPathOf(const std::filesystem::path& exr_path) {
        std::filesystem::path png = exr_path;
        png.replace_extension(".png");
        return png;
    }
    /// The bytes SaveState appends for a film of width x height (`aov`: with AOV buffers).
    static uint64_t StateBytes(int width, int height, bool aov) {
        return 64 + uint64_t(width) * uint64_t(height) * (5 * 8 + (aov ? 7 * 4 + 4 : 0));
    }
    /// Appends the sums (not the output settings) to `out`, for a checkpoint. Not concurrent with
    /// adds.
    void SaveState(ByteWriter* out) const;
    /// Replaces the sums with those SaveState wrote. Errors: DataLoss for a film of another size
    /// or other channels, or truncated bytes. Not concurrent with adds.
    Status LoadState(ByteReader* in);
    /// Combines this film with the films of the other processes of a distributed render: each
    /// buffer of sums is replaced by what the given function makes of it (the sum over the
    /// processes, in every one). Errors: the functions'. Not concurrent with adds.
    Status CombineSums(const std::function<Status(std::span<double>)>& sum_doubles,
                       const std::function<Status(std::span<float>)>& sum_floats,
                       const std::function<Status(std::span<uint32_t>)>& sum_counts);
    /// Sets every sum to zero: a process of a distributed render whose samples another process's
    /// film now holds (RenderSession's checkpoints). Not concurrent with adds.
    void Clear();
    /// Linear RGB of the output space (sRGB primaries) after white balance, per pixel.
    std::vector<float> LinearRgb() const;

  private:
    int width_, height_;
    OutputConfig output_;
    double spp_ = 1;
    std::unique_ptr<std::atomic<double>[]> xyz_;
    std::unique_ptr<std::atomic<double>[]> y_half_;  // per pixel, the luminance of each half
    std::unique_ptr<std::atomic<float>[]> aov_;      // albedo rgb, normal xyz, depth: 7 per pixel
    std::unique_ptr<std::atomic<uint32_t>[]> aov_count_;
};

}  // namespace nave::render
