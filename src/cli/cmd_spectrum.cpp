// `nave spectrum`: the colour of a measured reflectance or transmittance under a chosen light (XYZ,
// CIELAB, 8-bit sRGB), to compare a sample in a light booth with what nave will render.
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "src/cli/commands.h"
#include "src/core/color.h"
#include "src/core/illuminant.h"
#include "src/core/log.h"
#include "src/render/scene/sun/sun.h"

namespace nave::cli {

namespace {

struct SpectrumOptions {
    std::string file;
    std::string illuminant = "D65";
    bool json = false;
};

/// "D65", "A", "D50", "blackbody:3000", "sun:LAT,LON,TIME" (direct sunlight at that place and
/// time).
StatusOr<Spectrum> ParseIlluminant(const std::string& spec) {
    if (spec.rfind("sun:", 0) != 0) return NamedIlluminant(spec);
    std::string rest = spec.substr(4);
    size_t c1 = rest.find(','), c2 = c1 == std::string::npos ? c1 : rest.find(',', c1 + 1);
    if (c2 == std::string::npos)
        return InvalidArgumentError(
            "illuminant '{}': expected sun:LAT,LON,TIME (e.g. "
            "sun:48.85,2.35,2024-06-21T12:00+02:00)",
            spec);
    SunInput in;
    try {
        size_t used = 0;
        in.latitude_deg = std::stod(rest.substr(0, c1), &used);
        if (used != c1) throw std::invalid_argument("lat");
        in.longitude_deg = std::stod(rest.substr(c1 + 1, c2 - c1 - 1), &used);
        if (used != c2 - c1 - 1) throw std::invalid_argument("lon");
    } catch (const std::exception&) {
        return InvalidArgumentError("illuminant '{}': latitude and longitude must be numbers",
                                    spec);
    }
    NAVE_ASSIGN_OR_RETURN(in.time, ParseIso8601(rest.substr(c2 + 1)));
    NAVE_ASSIGN_OR_RETURN(Sun sun, ComputeSun(in));
    if (sun.direct_normal_irradiance.MaxValue() <= 0)
        return InvalidArgumentError("illuminant '{}': the sun is below the horizon then", spec);
    return sun.direct_normal_irradiance;
}

Status RunSpectrum(const SpectrumOptions& o) {
    NAVE_ASSIGN_OR_RETURN(Spectrum illuminant, ParseIlluminant(o.illuminant));
    StatusOr<SpectraTable> table = LoadSpectraCsv(o.file);
    if (!table.ok()) {
        // A malformed file is bad data (exit 1), not bad usage.
        if (table.status().code() == StatusCode::kInvalidArgument)
            return Status(StatusCode::kDataLoss, table.status().message());
        return table.status();
    }
    if (table->lambda_nm.front() > 400 || table->lambda_nm.back() < 700)
        log::Warning("{}: data covers {}-{} nm only; values are held constant outside it", o.file,
                     table->lambda_nm.front(), table->lambda_nm.back());
    Vec3d white = ReflectanceToXYZ(Spectrum::Constant(1.f), illuminant);
    Chromaticity white_xy = XYZToChromaticity(white);
    // The light-booth match: an observer adapted to the booth's light sees its white as white, so
    // the sample's sRGB is white-balanced (Bradford) from the illuminant to sRGB's D65.
    Mat3d to_srgb = WhiteBalancedXyzToRgb(RgbColorSpace::Srgb(), white_xy);
    std::string out;
    if (o.json)
        out = fmt::format("{{\n  \"illuminant\": \"{}\",\n  \"samples\": [\n", o.illuminant);
    else
        out = fmt::format(
            "illuminant {} (white x {:.4f}, y {:.4f}); XYZ with the perfect white at Y = 100\n"
            "{:<20} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}  {:<15} {}\n",
            o.illuminant, white_xy.x, white_xy.y, "sample", "X", "Y", "Z", "L*", "a*", "b*",
            "sRGB (8-bit)", "hex");
    for (size_t c = 0; c < table->names.size(); ++c) {
        Spectrum s = table->ToSpectrum(int(c));
        Vec3d xyz = ReflectanceToXYZ(s, illuminant);
        Vec3d lab = XYZToLab(xyz, white);
        std::array<uint8_t, 3> rgb = LinearSrgbTo8Bit(to_srgb * xyz);
        std::string hex = fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
        if (o.json) {
            out += fmt::format(
                "    {{\"name\": \"{}\", \"XYZ\": [{:.4f}, {:.4f}, {:.4f}], \"Lab\": [{:.3f}, "
                "{:.3f}, "
                "{:.3f}], \"sRGB8\": [{}, {}, {}], \"hex\": \"{}\"}}{}\n",
                table->names[c], 100 * xyz.x, 100 * xyz.y, 100 * xyz.z, lab.x, lab.y, lab.z, rgb[0],
                rgb[1], rgb[2], hex, c + 1 < table->names.size() ? "," : "");
        } else {
            out +=
                fmt::format("{:<20} {:8.3f} {:8.3f} {:8.3f} {:8.3f} {:8.3f} {:8.3f}  {:<15} {}\n",
                            table->names[c], 100 * xyz.x, 100 * xyz.y, 100 * xyz.z, lab.x, lab.y,
                            lab.z, fmt::format("{} {} {}", rgb[0], rgb[1], rgb[2]), hex);
        }
    }
    if (o.json) out += "  ]\n}\n";
    std::fputs(out.c_str(), stdout);
    return Status::Ok();
}

}  // namespace

void RegisterSpectrumCommand(CLI::App& app, CommandRun& run) {
    auto o = std::make_shared<SpectrumOptions>();
    CLI::App* cmd = app.add_subcommand(
        "spectrum",
        "Colour (XYZ, CIELAB, sRGB) of measured reflectance/transmittance spectra under a light");
    cmd->add_option("file", o->file,
                    "CSV: wavelength_nm then one column per sample; # comments; header row")
        ->required();
    cmd->add_option(
        "--illuminant", o->illuminant,
        "D65 (default), D50, A, E, D<cct>, blackbody:<K>, or sun:LAT,LON,TIME (direct sunlight)");
    cmd->add_flag("--json", o->json, "Print JSON");
    cmd->callback([&run, o] { run = [o] { return RunSpectrum(*o); }; });
}

}  // namespace nave::cli
