// `nave compare A.exr B.exr`: how far apart two renders are, in the terms docs/render.md uses to
// judge noise: each image's mean luminance, their ratio, and the relative mean squared error of one
// render estimated from a pair that differs only in the seed (or, with --reference, of A against
// B).
#include <fmt/format.h>

#include <algorithm>
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

/// The luminance of an image's R, G, B channels, per pixel.
StatusOr<std::vector<float>> ReadLuminance(const std::string& path, int* width, int* height) {
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
    std::vector<float> y(size_t(image.width) * image.height);
    for (size_t p = 0; p < y.size(); ++p) {
        const float* px = &image.pixels[p * nc];
        y[p] = float(LuminanceOfLinearSrgb(px[channel[0]], px[channel[1]], px[channel[2]]));
    }
    *width = image.width;
    *height = image.height;
    return y;
}

Status RunCompare(const CompareOptions& o) {
    if (o.identical) return CompareIdentical(o);
    int wa = 0, ha = 0, wb = 0, hb = 0;
    NAVE_ASSIGN_OR_RETURN(std::vector<float> a, ReadLuminance(o.a, &wa, &ha));
    NAVE_ASSIGN_OR_RETURN(std::vector<float> b, ReadLuminance(o.b, &wb, &hb));
    if (wa != wb || ha != hb)
        return InvalidArgumentError("{} is {}x{} but {} is {}x{}: compare images of one size", o.a,
                                    wa, ha, o.b, wb, hb);
    a = BoxBlur(a, wa, ha, o.blur_radius);
    b = BoxBlur(b, wb, hb, o.blur_radius);
    const double mean_a = FiniteMean(a), mean_b = FiniteMean(b);
    const double ratio = mean_a > 0 ? mean_b / mean_a : 0.0;
    const double rel_mse = o.reference ? RelMseAgainst(a, b) : PairRelMse(a, b);
    const char* what = o.reference ? "relmse_against_reference" : "relmse_of_one";
    if (o.json) {
        std::printf(
            "{\"mean_luminance_a\": %.9g, \"mean_luminance_b\": %.9g, \"ratio_b_to_a\": %.6f, "
            "\"blur_radius\": %d, \"%s\": %.6g}\n",
            mean_a, mean_b, ratio, o.blur_radius, what, rel_mse);
        return Status::Ok();
    }
    std::printf("%s: mean luminance %.6g\n%s: mean luminance %.6g (%.4f of the first)\n",
                o.a.c_str(), mean_a, o.b.c_str(), mean_b, ratio);
    if (o.blur_radius > 0)
        std::printf("both blurred over %d pixels around each pixel\n", o.blur_radius);
    if (o.reference) {
        std::printf("relMSE of %s against %s: %.4g\n", o.a.c_str(), o.b.c_str(), rel_mse);
    } else {
        std::printf("relMSE of one render (a pair that differs only in the seed): %.4g\n", rel_mse);
    }
    return Status::Ok();
}

}  // namespace

void RegisterCompareCommand(CLI::App& app, CommandRun& run) {
    auto o = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand(
        "compare",
        "How far apart two renders are: mean luminance of each and the relative mean squared error "
        "of one "
        "render estimated from two that differ only in the seed (docs/render.md, \"Noise\")");
    cmd->add_option("A", o->a, "First image (EXR, linear RGB)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("B", o->b, "Second image, same size")->required()->check(CLI::ExistingFile);
    cmd->add_flag(
        "--reference", o->reference,
        "B is a converged reference: report A's relMSE against it instead of the pair estimate");
    cmd->add_option(
           "--blur", o->blur_radius,
           "Box-blur both images over this many pixels around each pixel first (default 0)")
        ->check(CLI::Range(0, 1000));
    cmd->add_flag("--json", o->json, "Print JSON");
    cmd->add_flag(
        "--identical", o->identical,
        "Only check that A and B hold the same value in every channel of every pixel, bit for "
        "bit (exit code 1 and the first difference if not)");
    cmd->callback([&run, o] { run = [o] { return RunCompare(*o); }; });
}

}  // namespace nave::cli
