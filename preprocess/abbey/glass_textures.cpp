#include "preprocess/abbey/glass_textures.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "src/core/pane.h"
#include "src/core/spectrum.h"
#include "src/core/spectrum_data.h"
#include "src/imaging/image_io.h"

namespace nave::preprocess::abbey {
namespace {

constexpr int kWidth = 96,
              kHeight = 192;  // texels across and up a window (windows are about twice as tall)
constexpr float kFirstBandNm = 380.f, kBandStepNm = 20.f;
constexpr int kBands = 21;                      // 380, 400, ..., 780 nm
constexpr int kCellsAcross = 8, kCellsUp = 16;  // thickness undulations per window

/// A number in [0, 1) from a lattice point (SplitMix64 finaliser, Steele et al. 2014).
double LatticeValue(uint64_t seed, int x, int y) {
    uint64_t z = seed * 0x9e3779b97f4a7c15ull + uint64_t(uint32_t(x)) * 0xbf58476d1ce4e5b9ull +
                 uint64_t(uint32_t(y)) * 0x94d049bb133111ebull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
}

/// Smooth value noise in [-1, 1] at (u, v) in [0, 1]²: lattice values blended with smoothstep
/// weights.
double Undulation(uint64_t seed, double u, double v) {
    const double x = u * kCellsAcross, y = v * kCellsUp;
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    auto smooth = [](double t) { return t * t * (3 - 2 * t); };
    const double fx = smooth(x - x0), fy = smooth(y - y0);
    auto at = [&](int dx, int dy) { return LatticeValue(seed, x0 + dx, y0 + dy); };
    const double top = at(0, 0) + (at(1, 0) - at(0, 0)) * fx,
                 bottom = at(0, 1) + (at(1, 1) - at(0, 1)) * fx;
    return 2 * (top + (bottom - top) * fy) - 1;
}

}  // namespace

std::string GlassTextureName(std::string_view material) {
    return std::string(material) + ".transmittance.exr";
}

Status WriteGlassTextures(const std::filesystem::path& dir) {
    const SpectraTable& table = EmbeddedSpectraTable("stained_glass_approx.csv");
    std::string centres;
    for (int b = 0; b < kBands; ++b) {
        if (b > 0) centres += ',';
        centres += fmt::format("{:g}", kFirstBandNm + b * kBandStepNm);
    }
    uint64_t seed = 1;
    for (const char* name :
         {"glass_clear", "glass_blue", "glass_red", "glass_yellow", "glass_green"}) {
        NAVE_ASSIGN_OR_RETURN(Spectrum total, table.ToSpectrum(name));
        // The CSV's total transmittance was built for faces of R = 0.04 (n = 1.5): inverted with
        // the same R.
        double tau0[kBands];
        for (int b = 0; b < kBands; ++b)
            tau0[b] =
                PaneInternalTransmittance(total.Evaluate(kFirstBandNm + b * kBandStepNm), 0.04);
        imaging::FloatImage image;
        image.width = kWidth;
        image.height = kHeight;
        for (int b = 0; b < kBands; ++b) image.channels.push_back(imaging::BandChannelName(b));
        image.pixels.resize(size_t(kWidth) * kHeight * kBands);
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                // Blown medieval glass is far from flat: its thickness varies within a piece by
                // tens of per cent (R. G. Newton & S. Davison, Conservation of Glass, 1989, ch. 3).
                // The absorbance is proportional to the thickness (Beer-Lambert), so τ = τ0^(d /
                // d0); d / d0 = 1 ± 0.3 here.
                const double relative =
                    1 + 0.3 * Undulation(seed, (x + 0.5) / kWidth, (y + 0.5) / kHeight);
                float* px = &image.pixels[(size_t(y) * kWidth + size_t(x)) * kBands];
                for (int b = 0; b < kBands; ++b) px[b] = float(std::pow(tau0[b], relative));
            }
        }
        NAVE_RETURN_IF_ERROR(imaging::WriteTiledExr(dir / GlassTextureName(name), image, 64,
                                                    {{imaging::kBandCentresAttribute, centres}}));
        ++seed;
    }
    return Status::Ok();
}

}  // namespace nave::preprocess::abbey
