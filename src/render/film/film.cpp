#include "src/render/film/film.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <span>

#include "src/core/atomic_add.h"
#include "src/core/byte_stream.h"
#include "src/core/check.h"
#include "src/imaging/image_io.h"

namespace nave::render {
namespace {

/// The white the image is balanced for: none keeps XYZ -> sRGB as is (equal-energy light looks
/// slightly pink, as in pbrt-v4 without white balance); otherwise the named illuminant's
/// chromaticity, or the scene's own light, is mapped to the sRGB white by the output's adaptation
/// transform.
Mat3d OutputMatrix(const OutputConfig& output) {
    const RgbColorSpace& srgb = RgbColorSpace::Srgb();
    const std::string& white_balance = output.white_balance;
    if (white_balance == "none") return srgb.xyz_to_rgb();
    if (white_balance == "scene") {
        NAVE_CHECK(output.scene_white.has_value())
            << "white_balance = scene without the scene's white";
        return WhiteBalancedXyzToRgb(srgb, *output.scene_white, output.adaptation);
    }
    double cct = white_balance == "D65"   ? 6504.0
                 : white_balance == "D50" ? 5003.0
                                          : std::stod(white_balance);
    Chromaticity white = XYZToChromaticity(
        SpectrumToXYZ(Spectrum::CieIlluminantD(std::clamp(cct, 4000.0, 25000.0))));
    return WhiteBalancedXyzToRgb(srgb, white, output.adaptation);
}

}  // namespace

std::vector<uint8_t> DisplayImage(const std::vector<float>& rgb, const OutputConfig& output) {
    const size_t pixels = rgb.size() / 3;
    double log_sum = 0;
    size_t count = 0;
    for (size_t p = 0; p < pixels; ++p) {
        double y = 0.2126 * rgb[3 * p] + 0.7152 * rgb[3 * p + 1] + 0.0722 * rgb[3 * p + 2];
        if (y > 0 && std::isfinite(y)) {
            log_sum += std::log(1e-6 + y);
            ++count;
        }
    }
    const double key = count ? std::exp(log_sum / double(count)) : 1.0;
    double ev = output.exposure_ev;
    if (output.exposure == OutputConfig::Exposure::kAuto) {
        // The log-average luminance to middle grey 0.18 (Reinhard et al. 2002, "Photographic tone
        // reproduction", eq. 1-2).
        ev += std::log2(0.18 / key);
    } else {
        // Luminance in cd/m²: Km = 683.002 lm/W times ∫ȳ L, and the film's Y is ∫ȳ L / ∫ȳ.
        const double to_cd = 683.002 * CieYIntegral();
        // A reflected-light meter's EV100 = log2(L S / K), S = 100, K = 12.5 (ISO 2720:1974),
        // unless given; the sensor saturates at L_max = 78 / (q S) 2^EV100 with q = 0.65
        // (saturation-based speed, ISO 12232:2006; Lagarde & de Rousiers 2014, "Moving Frostbite to
        // PBR", eq. 12).
        const double ev100 = output.ev100 ? *output.ev100 : std::log2(key * to_cd * 100 / 12.5);
        const double l_max = 78.0 / (0.65 * 100) * std::exp2(ev100);
        ev += std::log2(to_cd / l_max);
    }
    std::vector<uint8_t> png(pixels * 3);
    for (size_t p = 0; p < pixels; ++p) {
        Vec3d c = ApplyExposure(Vec3d(rgb[3 * p], rgb[3 * p + 1], rgb[3 * p + 2]), ev);
        if (output.tone == OutputConfig::Tone::kHuePreserving) {
            // Compress the largest channel (Reinhard et al. 2002 eq. 4 with a white of 4) and scale
            // the pixel with it: the channels keep their ratios, so a saturated glass colour keeps
            // its hue and saturation where clipping each channel would turn it toward yellow or
            // white.
            for (int i = 0; i < 3; ++i) c[i] = std::max(0.0, c[i]);
            const double m = std::max({c.x, c.y, c.z});
            constexpr double kWhite = 4;
            if (m > 0) c = c * ((1 + m / (kWhite * kWhite)) / (1 + m));
        }
        std::array<uint8_t, 3> v = LinearSrgbTo8Bit(c);
        for (int i = 0; i < 3; ++i) png[3 * p + i] = v[i];
    }
    return png;
}

Film::Film(int width, int height, const OutputConfig& output)
    : width_(width), height_(height), output_(output) {
    xyz_.reset(new std::atomic<double>[pixel_count() * 3]);
    for (size_t i = 0; i < pixel_count() * 3; ++i) xyz_[i].store(0, std::memory_order_relaxed);
    y_half_.reset(new std::atomic<double>[pixel_count() * 2]);
    for (size_t i = 0; i < pixel_count() * 2; ++i) y_half_[i].store(0, std::memory_order_relaxed);
    if (output_.aov_albedo || output_.aov_normal || output_.aov_depth) {
        aov_.reset(new std::atomic<float>[pixel_count() * 7]);
        aov_count_.reset(new std::atomic<uint32_t>[pixel_count()]);
        for (size_t i = 0; i < pixel_count() * 7; ++i) aov_[i].store(0, std::memory_order_relaxed);
        for (size_t i = 0; i < pixel_count(); ++i)
            aov_count_[i].store(0, std::memory_order_relaxed);
    }
}

void Film::AddXYZ(uint32_t pixel, const Vec3d& xyz, int half) {
    if (!(std::isfinite(xyz.x) && std::isfinite(xyz.y) && std::isfinite(xyz.z))) return;
    for (int c = 0; c < 3; ++c) AtomicAdd(xyz_[3 * size_t(pixel) + c], xyz[c]);
    if (half == 0 || half == 1) AtomicAdd(y_half_[2 * size_t(pixel) + size_t(half)], xyz.y);
}

void Film::AddAov(uint32_t pixel, const Vec3f& albedo, const Vec3f& normal, float depth) {
    if (!aov_) return;
    const float v[7] = {albedo.x, albedo.y, albedo.z, normal.x, normal.y, normal.z, depth};
    for (int c = 0; c < 7; ++c) AtomicAdd(aov_[7 * size_t(pixel) + c], v[c]);
    aov_count_[pixel].fetch_add(1, std::memory_order_relaxed);
}

Vec3d Film::SumXYZ(uint32_t pixel) const {
    return {xyz_[3 * size_t(pixel)].load(std::memory_order_relaxed),
            xyz_[3 * size_t(pixel) + 1].load(std::memory_order_relaxed),
            xyz_[3 * size_t(pixel) + 2].load(std::memory_order_relaxed)};
}

namespace {

// Value by value, in PutArray's layout: a copy of a large film in between would add its size to
// the memory a checkpoint takes.
template <typename T>
void PutAtomics(ByteWriter* out, const std::atomic<T>* values, size_t count) {
    out->Put(uint64_t(count));
    for (size_t i = 0; i < count; ++i) out->Put(values[i].load(std::memory_order_relaxed));
}

template <typename T>
Status GetAtomics(ByteReader* in, std::atomic<T>* values, size_t count, std::string_view field) {
    NAVE_RETURN_IF_ERROR(in->GetCount(count, field));
    for (size_t i = 0; i < count; ++i) {
        T value;
        NAVE_RETURN_IF_ERROR(in->Get(&value, field));
        values[i].store(value, std::memory_order_relaxed);
    }
    return Status::Ok();
}

// Replaces `count` atomics by what `sum` makes of their values (their sums over the films of a
// distributed render).
template <typename T>
Status SumAtomics(std::atomic<T>* values, size_t count,
                  const std::function<Status(std::span<T>)>& sum) {
    std::vector<T> plain(count);
    for (size_t i = 0; i < count; ++i) plain[i] = values[i].load(std::memory_order_relaxed);
    NAVE_RETURN_IF_ERROR(sum(plain));
    for (size_t i = 0; i < count; ++i) values[i].store(plain[i], std::memory_order_relaxed);
    return Status::Ok();
}

}  // namespace

Status Film::CombineSums(const std::function<Status(std::span<double>)>& sum_doubles,
                         const std::function<Status(std::span<float>)>& sum_floats,
                         const std::function<Status(std::span<uint32_t>)>& sum_counts) {
    NAVE_RETURN_IF_ERROR(SumAtomics(xyz_.get(), pixel_count() * 3, sum_doubles));
    NAVE_RETURN_IF_ERROR(SumAtomics(y_half_.get(), pixel_count() * 2, sum_doubles));
    if (aov_) {
        NAVE_RETURN_IF_ERROR(SumAtomics(aov_.get(), pixel_count() * 7, sum_floats));
        NAVE_RETURN_IF_ERROR(SumAtomics(aov_count_.get(), pixel_count(), sum_counts));
    }
    return Status::Ok();
}

void Film::Clear() {
    for (size_t i = 0; i < pixel_count() * 3; ++i) xyz_[i].store(0, std::memory_order_relaxed);
    for (size_t i = 0; i < pixel_count() * 2; ++i) y_half_[i].store(0, std::memory_order_relaxed);
    if (aov_) {
        for (size_t i = 0; i < pixel_count() * 7; ++i) aov_[i].store(0, std::memory_order_relaxed);
        for (size_t i = 0; i < pixel_count(); ++i)
            aov_count_[i].store(0, std::memory_order_relaxed);
    }
}

void Film::SaveState(ByteWriter* out) const {
    out->Reserve(StateBytes(width_, height_, aov_ != nullptr));
    out->Put(int32_t(width_));
    out->Put(int32_t(height_));
    out->Put(uint8_t(aov_ != nullptr));
    PutAtomics(out, xyz_.get(), pixel_count() * 3);
    PutAtomics(out, y_half_.get(), pixel_count() * 2);
    if (aov_) {
        PutAtomics(out, aov_.get(), pixel_count() * 7);
        PutAtomics(out, aov_count_.get(), pixel_count());
    }
}

Status Film::LoadState(ByteReader* in) {
    int32_t width = 0, height = 0;
    uint8_t has_aov = 0;
    NAVE_RETURN_IF_ERROR(in->Get(&width, "width"));
    NAVE_RETURN_IF_ERROR(in->Get(&height, "height"));
    NAVE_RETURN_IF_ERROR(in->Get(&has_aov, "AOV flag"));
    if (width != width_ || height != height_ || bool(has_aov) != (aov_ != nullptr)) {
        return DataLossError("{}: a film of {}x{}{}, this render's is {}x{}{}", in->what(), width,
                             height, has_aov ? " with AOVs" : "", width_, height_,
                             aov_ ? " with AOVs" : "");
    }
    NAVE_RETURN_IF_ERROR(GetAtomics(in, xyz_.get(), pixel_count() * 3, "XYZ sums"));
    NAVE_RETURN_IF_ERROR(GetAtomics(in, y_half_.get(), pixel_count() * 2, "half sums"));
    if (aov_) {
        NAVE_RETURN_IF_ERROR(GetAtomics(in, aov_.get(), pixel_count() * 7, "AOV sums"));
        NAVE_RETURN_IF_ERROR(GetAtomics(in, aov_count_.get(), pixel_count(), "AOV counts"));
    }
    return in->ExpectEnd();
}

std::vector<float> Film::LinearRgb() const {
    Mat3d m = OutputMatrix(output_);
    std::vector<float> rgb(pixel_count() * 3);
    for (size_t p = 0; p < pixel_count(); ++p) {
        Vec3d c = m * PixelXYZ(uint32_t(p));
        for (int i = 0; i < 3; ++i) rgb[3 * p + i] = float(c[i]);
    }
    return rgb;
}

Status Film::Write(const std::filesystem::path& exr_path,
                   const std::vector<std::pair<std::string, std::string>>& metadata) const {
    std::vector<float> rgb = LinearRgb();
    imaging::FloatImage image;
    image.width = width_;
    image.height = height_;
    image.channels = {"R", "G", "B"};
    if (aov_) {
        if (output_.aov_albedo)
            image.channels.insert(image.channels.end(), {"albedo.R", "albedo.G", "albedo.B"});
        if (output_.aov_normal)
            image.channels.insert(image.channels.end(), {"normal.X", "normal.Y", "normal.Z"});
        if (output_.aov_depth) image.channels.push_back("Z");
    }
    const size_t nc = image.channels.size();
    image.pixels.resize(pixel_count() * nc);
    for (size_t p = 0; p < pixel_count(); ++p) {
        float* out = &image.pixels[p * nc];
        for (int i = 0; i < 3; ++i) out[i] = rgb[3 * p + i];
        if (!aov_) continue;
        size_t k = 3;
        uint32_t n = std::max(1u, aov_count_[p].load(std::memory_order_relaxed));
        auto aov = [&](int c) {
            return aov_[7 * p + c].load(std::memory_order_relaxed) / float(n);
        };
        if (output_.aov_albedo)
            for (int c = 0; c < 3; ++c) out[k++] = aov(c);
        if (output_.aov_normal) {
            Vec3f nrm(aov(3), aov(4), aov(5));
            float len = Length(nrm);
            if (len > 0) nrm = nrm / len;
            for (int c = 0; c < 3; ++c) out[k++] = nrm[c];
        }
        if (output_.aov_depth) out[k++] = aov_count_[p].load() ? aov(6) : INFINITY;
    }
    NAVE_ASSIGN_OR_RETURN(imaging::EncodedImage exr, imaging::EncodeExr(exr_path, image, metadata));

    const std::vector<uint8_t> png = DisplayImage(rgb, output_);
    NAVE_ASSIGN_OR_RETURN(
        imaging::EncodedImage display,
        imaging::EncodeRgb8(DisplayPathOf(exr_path), width_, height_, png, metadata));
    // Both or neither: an EXR and a PNG of different renders side by side would mislead. Moved,
    // not copied: the encoded EXR is megabytes, under the render's memory budget.
    const imaging::EncodedImage both[] = {std::move(exr), std::move(display)};
    return imaging::WriteImages(both);
}

}  // namespace nave::render
