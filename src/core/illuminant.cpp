#include "src/core/illuminant.h"

#include <cctype>
#include <charconv>
#include <string>

#include "src/core/spectrum_data.h"

namespace nave {

const Spectrum& IlluminantD65() {
    static const Spectrum s = EmbeddedSpectraTable("cie_illuminant_d65.csv").ToSpectrum(0);
    return s;
}

const Spectrum& IlluminantD50() {
    // CIE 15:2004 §3.1: D50 is the daylight of nominal CCT 5000 K, computed at 5000 × 1.4388/1.4380
    // K since the change of c2 in the ITS-90.
    static const Spectrum s = Spectrum::CieIlluminantD(5000.0 * 1.4388 / 1.4380);
    return s;
}

const Spectrum& IlluminantA() {
    // CIE 15:2004 eq. (3.1): S_A(λ) = 100 (560/λ)^5 (e^(c2/(2848·560)) - 1) / (e^(c2/(2848 λ)) -
    // 1), c2 = 1.435e7 nm K (the defining form; equivalent to 2856 K with c2 = 1.4388e7 nm K).
    static const Spectrum s = Spectrum::FromFunction([](double l) {
        constexpr double kC2 = 1.435e7;
        constexpr double kT = 2848.0;
        return 100.0 * std::pow(560.0 / l, 5.0) * std::expm1(kC2 / (kT * 560.0)) /
               std::expm1(kC2 / (kT * l));
    });
    return s;
}

const Spectrum& IlluminantE() {
    static const Spectrum s = Spectrum::Constant(1.f);
    return s;
}

namespace {

bool ParseNumber(std::string_view s, double* v) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *v);
    return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(*v);
}

}  // namespace

StatusOr<Spectrum> NamedIlluminant(std::string_view name) {
    std::string n;
    for (char c : name) n += char(std::toupper(static_cast<unsigned char>(c)));
    if (n == "D65") return IlluminantD65();
    if (n == "D50") return IlluminantD50();
    if (n == "A") return IlluminantA();
    if (n == "E") return IlluminantE();
    auto bad = [&]() {
        return InvalidArgumentError(
            "unknown illuminant '{}' (expected D65, D50, A, E, D<cct kelvin 4000-25000> such as "
            "D5500, or blackbody:<kelvin>)",
            name);
    };
    double v = 0;
    if (n.rfind("BLACKBODY:", 0) == 0) {
        if (!ParseNumber(std::string_view(n).substr(10), &v) || v <= 0) return bad();
        return Spectrum::Blackbody(v);
    }
    if (n.size() > 1 && n[0] == 'D') {
        std::string_view rest = std::string_view(n).substr(n[1] == ':' ? 2 : 1);
        if (!ParseNumber(rest, &v)) return bad();
        // "D55" style names mean hundreds of kelvin with the c2 correction (CIE 15:2004 §3.1).
        if (v < 100) v = v * 100.0 * 1.4388 / 1.4380;
        if (v < 4000 || v > 25000) return bad();
        return Spectrum::CieIlluminantD(v);
    }
    return bad();
}

Chromaticity IlluminantChromaticity(const Spectrum& illuminant) {
    return XYZToChromaticity(SpectrumToXYZ(illuminant));
}

}  // namespace nave
