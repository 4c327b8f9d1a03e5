// `nave compare A.exr B.exr`: how far apart two renders are, in the terms docs/render.md uses to
// judge noise: each image's mean luminance, their ratio, and the relative mean squared error of one
// render estimated from a pair that differs only in the seed (or, with --reference, of A against
// B), on luminance, on RGB and on RGB after a box blur (which removes pixel noise and keeps error
// that spans many pixels: photon discs, blotches), and the mean of each region of a 3 x 3 grid, so
// that a bias in part of the image shows.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "src/cli/commands.h"
#include "src/core/image_error.h"
#include "src/imaging/image_io.h"

namespace nave::cli {
namespace {

struct CompareOptions {
    std::string a, b;
    bool reference = false;
    int blur_radius = 0;
    bool json = false;
    bool identical = false;
};

/// --identical: whether every channel of every pixel of the two images has the same bits (a
/// resumed render against an uninterrupted one, say). Half-float EXR channels widen to float
/// exactly, so equal floats are equal stored values.
Status CompareIdentical(const CompareOptions& o) {
    NAVE_ASSIGN_OR_RETURN(imaging::FloatImage a, imaging::ReadImage(o.a));
    NAVE_ASSIGN_OR_RETURN(imaging::FloatImage b, imaging::ReadImage(o.b));
    if (a.width != b.width || a.height != b.height || a.channels != b.channels) {
        return DataLossError(
            "{} ({}x{}, {} channels) and {} ({}x{}, {} channels) differ in size or "
            "channels",
            o.a, a.width, a.height, a.channels.size(), o.b, b.width, b.height, b.channels.size());
    }
    const size_t nc = a.channels.size();
    uint64_t differing = 0;
    size_t first = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        if (std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(float)) == 0) continue;
        if (differing++ == 0) first = i;
    }
    if (differing == 0) {
        std::printf("%s and %s are identical (%dx%d, %zu channels)\n", o.a.c_str(), o.b.c_str(),
                    a.width, a.height, nc);
        return Status::Ok();
    }
    const size_t pixel = first / nc;
    return DataLossError(
        "{} and {} differ in {} of {} values; the first at pixel ({}, {}) channel "
        "{}: {} vs {}",
        o.a, o.b, differing, a.pixels.size(), pixel % size_t(a.width), pixel / size_t(a.width),
        a.channels[first % nc], a.pixels[first], b.pixels[first]);
}

/// An image's R, G and B channels and their luminance, per pixel.
struct RgbImage {
    int width = 0, height = 0;
    std::array<std::vector<float>, 3> rgb;
    std::vector<float> luminance;
};

StatusOr<RgbImage> ReadRgb(const std::string& path) {
    NAVE_ASSIGN_OR_RETURN(imaging::FloatImage image, imaging::ReadImage(path));
    int channel[3] = {-1, -1, -1};
    for (size_t c = 0; c < image.channels.size(); ++c) {
        for (int k = 0; k < 3; ++k) {
            if (image.channels[c] == std::string(1, "RGB"[k])) channel[k] = int(c);
        }
    }
    if (channel[0] < 0 || channel[1] < 0 || channel[2] < 0)
        return InvalidArgumentError("{}: expected channels R, G and B", path);
    const size_t nc = image.channels.size();
    const size_t pixels = size_t(image.width) * size_t(image.height);
    RgbImage out;
    out.width = image.width;
    out.height = image.height;
    for (auto& plane : out.rgb) plane.resize(pixels);
    out.luminance.resize(pixels);
    for (size_t p = 0; p < pixels; ++p) {
        const float* px = &image.pixels[p * nc];
        for (int k = 0; k < 3; ++k) out.rgb[size_t(k)][p] = px[channel[k]];
        out.luminance[p] =
            float(LuminanceOfLinearSrgb(px[channel[0]], px[channel[1]], px[channel[2]]));
    }
    return out;
}

/// The box blur a comparison on RGB reports beside the plain one when --blur does not choose:
/// 4 pixels, a 9 x 9 square, over which pixel noise falls some 80-fold.
constexpr int kDefaultRgbBlur = 4;
/// The regions whose mean luminance is compared: a grid of this many a side.
constexpr int kRegionsPerSide = 3;

/// The relMSE of `a` (of one render of a pair, or against the reference `b`) over R, G and B: the
/// mean of the three channels' relMSE, each box-blurred over `blur` pixels first.
double RgbRelMse(const RgbImage& a, const RgbImage& b, bool reference, int blur) {
    double sum = 0;
    for (size_t k = 0; k < 3; ++k) {
        const std::vector<float> ca = BoxBlur(a.rgb[k], a.width, a.height, blur);
        const std::vector<float> cb = BoxBlur(b.rgb[k], b.width, b.height, blur);
        sum += reference ? RelMseAgainst(ca, cb) : PairRelMse(ca, cb);
    }
    return sum / 3;
}

Status RunCompare(const CompareOptions& o) {
    if (o.identical) return CompareIdentical(o);
    NAVE_ASSIGN_OR_RETURN(RgbImage image_a, ReadRgb(o.a));
    NAVE_ASSIGN_OR_RETURN(RgbImage image_b, ReadRgb(o.b));
    if (image_a.width != image_b.width || image_a.height != image_b.height)
        return InvalidArgumentError("{} is {}x{} but {} is {}x{}: compare images of one size", o.a,
                                    image_a.width, image_a.height, o.b, image_b.width,
                                    image_b.height);
    const int w = image_a.width, h = image_a.height;
    const std::vector<float> a = BoxBlur(image_a.luminance, w, h, o.blur_radius);
    const std::vector<float> b = BoxBlur(image_b.luminance, w, h, o.blur_radius);
    const double mean_a = FiniteMean(a), mean_b = FiniteMean(b);
    const double ratio = mean_a > 0 ? mean_b / mean_a : 0.0;
    const double rel_mse = o.reference ? RelMseAgainst(a, b) : PairRelMse(a, b);
    const int rgb_blur = o.blur_radius > 0 ? o.blur_radius : kDefaultRgbBlur;
    const double rgb = RgbRelMse(image_a, image_b, o.reference, 0);
    const double rgb_blurred = RgbRelMse(image_a, image_b, o.reference, rgb_blur);
    const std::vector<double> regions_a =
        RegionMeans(image_a.luminance, w, h, kRegionsPerSide, kRegionsPerSide);
    const std::vector<double> regions_b =
        RegionMeans(image_b.luminance, w, h, kRegionsPerSide, kRegionsPerSide);
    const char* what = o.reference ? "relmse_against_reference" : "relmse_of_one";
    if (o.json) {
        std::string regions;
        for (size_t r = 0; r < regions_a.size(); ++r) {
            regions +=
                fmt::format("{}[{:.9g}, {:.9g}]", r > 0 ? ", " : "", regions_a[r], regions_b[r]);
        }
        std::printf(
            "{\"mean_luminance_a\": %.9g, \"mean_luminance_b\": %.9g, \"ratio_b_to_a\": %.6f, "
            "\"blur_radius\": %d, \"%s\": %.6g, \"%s_rgb\": %.6g, \"rgb_blur_radius\": %d, "
            "\"%s_rgb_blurred\": %.6g, \"region_grid\": %d, \"region_mean_luminance\": [%s]}\n",
            mean_a, mean_b, ratio, o.blur_radius, what, rel_mse, what, rgb, rgb_blur, what,
            rgb_blurred, kRegionsPerSide, regions.c_str());
        return Status::Ok();
    }
    std::printf("%s: mean luminance %.6g\n%s: mean luminance %.6g (%.4f of the first)\n",
                o.a.c_str(), mean_a, o.b.c_str(), mean_b, ratio);
    const std::string luminance_blur =
        o.blur_radius > 0 ? fmt::format(" (box-blurred over {} pixels)", o.blur_radius) : "";
    if (o.reference) {
        std::printf("relMSE of %s against %s:\n", o.a.c_str(), o.b.c_str());
    } else {
        std::printf("relMSE of one render (a pair that differs only in the seed):\n");
    }
    std::printf("  luminance%s %.4g\n  RGB %.4g\n  RGB box-blurred over %d pixels %.4g\n",
                luminance_blur.c_str(), rel_mse, rgb, rgb_blur, rgb_blurred);
    std::printf("mean luminance by region (%d x %d, top row first), second / first:\n",
                kRegionsPerSide, kRegionsPerSide);
    for (int row = 0; row < kRegionsPerSide; ++row) {
        std::string line = " ";
        for (int col = 0; col < kRegionsPerSide; ++col) {
            const size_t r = size_t(row * kRegionsPerSide + col);
            line += regions_a[r] > 0 ? fmt::format(" {:8.4f}", regions_b[r] / regions_a[r])
                                     : std::string("        -");
        }
        std::printf("%s\n", line.c_str());
    }
    return Status::Ok();
}

}  // namespace

void RegisterCompareCommand(CLI::App& app, CommandRun& run) {
    auto o = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand(
        "compare",
        "How far apart two renders are: mean luminance of each (and of each region of a 3 x 3 "
        "grid), and the relative mean squared error of one render estimated from two that differ "
        "only in the seed, on luminance, RGB and blurred RGB (docs/render.md, \"Noise\")");
    cmd->add_option("A", o->a, "First image (EXR, linear RGB)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("B", o->b, "Second image, same size")->required()->check(CLI::ExistingFile);
    cmd->add_flag(
        "--reference", o->reference,
        "B is a converged reference: report A's relMSE against it instead of the pair estimate");
    cmd->add_option(
           "--blur", o->blur_radius,
           "Box-blur both images' luminance over this many pixels around each pixel first, and "
           "the RGB comparison's blurred figure over as many (default 0; blurred RGB: 4)")
        ->check(CLI::Range(0, 1000));
    cmd->add_flag("--json", o->json, "Print JSON");
    cmd->add_flag(
        "--identical", o->identical,
        "Only check that A and B hold the same value in every channel of every pixel, bit for "
        "bit (exit code 1 and the first difference if not)");
    cmd->callback([&run, o] { run = [o] { return RunCompare(*o); }; });
}

}  // namespace nave::cli
