#include "src/render/scene/materials/ior.h"

#include <cctype>
#include <cmath>
#include <string>

#include "src/core/spectrum_data.h"

namespace nave {

Spectrum SellmeierIndex(double b1, double b2, double b3, double c1, double c2, double c3) {
    return Spectrum::FromFunction([&](double l_nm) {
        double l2 = (l_nm / 1000.0) * (l_nm / 1000.0);
        return std::sqrt(1.0 + b1 * l2 / (l2 - c1) + b2 * l2 / (l2 - c2) + b3 * l2 / (l2 - c3));
    });
}

Spectrum CauchyIndex(double a, double b_um2) {
    return Spectrum::FromFunction([&](double l_nm) {
        double l = l_nm / 1000.0;
        return a + b_um2 / (l * l);
    });
}

const Spectrum& Bk7Index() {
    static const Spectrum s = SellmeierIndex(1.03961212, 0.231792344, 1.01046945, 0.00600069867,
                                             0.0200179144, 103.560653);
    return s;
}

const Spectrum& SodaLimeIndex() {
    // Rubin (1985), Sol. Energy Mater. 12, 275, fit for clear glass valid 0.31-4.6 µm.
    static const Spectrum s = Spectrum::FromFunction([](double l_nm) {
        double l2 = (l_nm / 1000.0) * (l_nm / 1000.0);
        return 1.5130 - 0.003169 * l2 + 0.003962 / l2;
    });
    return s;
}

Spectrum AbsorptionPerMetre(const Spectrum& k) {
    return Spectrum::FromFunction(
        [&](double l_nm) { return 4.0 * M_PI * k.Evaluate(float(l_nm)) / (l_nm * 1e-9); });
}

const Spectrum& SodaLimeAbsorptionPerMetre() {
    static const Spectrum s =
        AbsorptionPerMetre(EmbeddedSpectraTable("glass_soda_lime_rubin1985.csv").ToSpectrum(0));
    return s;
}

const Spectrum& GreenSodaLimeAbsorptionPerMetre() {
    static const Spectrum s = AbsorptionPerMetre(
        EmbeddedSpectraTable("glass_soda_lime_green_rubin1985.csv").ToSpectrum(0));
    return s;
}

StatusOr<ComplexIndex> NamedMetal(std::string_view name) {
    std::string n;
    for (char c : name) n += char(std::tolower(static_cast<unsigned char>(c)));
    const char* file = nullptr;
    if (n == "au" || n == "gold") file = "metal_au_johnson_christy_1972.csv";
    if (n == "ag" || n == "silver") file = "metal_ag_johnson_christy_1972.csv";
    if (n == "cu" || n == "copper") file = "metal_cu_johnson_christy_1972.csv";
    if (n == "al" || n == "aluminium" || n == "aluminum") file = "metal_al_mcpeak_2015.csv";
    if (n == "pb" || n == "lead") file = "metal_pb_werner_2009.csv";
    if (!file)
        return NotFoundError("no optical constants for metal '{}' (known: Au, Ag, Cu, Al, Pb)",
                             name);
    const SpectraTable& t = EmbeddedSpectraTable(file);
    return ComplexIndex{t.ToSpectrum(0), t.ToSpectrum(1)};
}

}  // namespace nave
