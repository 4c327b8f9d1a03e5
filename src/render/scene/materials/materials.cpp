#include "src/render/scene/materials/materials.h"

#include <cmath>

#include "src/core/pane.h"
#include "src/core/spectrum_data.h"
#include "src/render/scene/materials/ior.h"

namespace nave {

Bxdf GetBxdf(const Material& m, SampledWavelengths& lambda) {
    return std::visit([&](const auto& mat) { return mat.GetBxdf(lambda); }, m);
}

float ThinGlassMaterial::InternalFromTotalTransmittance(float total_t, float eta) {
    return PaneInternalTransmittance(total_t, FrDielectric(1.f, eta));
}

ThinGlassMaterial ThinGlassMaterial::FromAbsorption(const Spectrum& eta,
                                                    const Spectrum& absorption_per_metre,
                                                    double thickness_m) {
    ThinGlassMaterial m;
    m.eta = eta;
    m.internal_transmittance = Spectrum::FromFunction([&](double l) {
        return std::exp(-double(absorption_per_metre.Evaluate(float(l))) * thickness_m);
    });
    return m;
}

ThinGlassMaterial ThinGlassMaterial::FromTotalTransmittance(const Spectrum& eta,
                                                            const Spectrum& total_transmittance) {
    ThinGlassMaterial m;
    m.eta = eta;
    m.internal_transmittance = Spectrum::FromFunction([&](double l) {
        float lf = float(l);
        return InternalFromTotalTransmittance(total_transmittance.Evaluate(lf), eta.Evaluate(lf));
    });
    return m;
}

namespace {

const char* const kNames[] = {"limestone",       "limestone_dark", "floor_tile_light",
                              "floor_tile_dark", "glass_clear",    "glass_blue",
                              "glass_red",       "glass_yellow",   "glass_green",
                              "glass_grisaille", "lead",           "wood",
                              "roof_slate",      "gold",           "silver",
                              "copper",          "aluminium",      "bk7",
                              "window_glass"};

ConductorMaterial Metal(std::string_view symbol, float alpha) {
    StatusOr<ComplexIndex> ci = NamedMetal(symbol);
    NAVE_CHECK(ci.ok()) << ci.status().ToString();
    ConductorMaterial m;
    m.eta = ci->eta;
    m.k = ci->k;
    m.alpha_x = m.alpha_y = alpha;
    return m;
}

}  // namespace

std::vector<std::string> BuiltinMaterialNames() { return {std::begin(kNames), std::end(kNames)}; }

StatusOr<Material> BuiltinMaterial(std::string_view name) {
    const SpectraTable& building = EmbeddedSpectraTable("stone_approx.csv");
    for (std::string_view n : {"limestone", "limestone_dark", "floor_tile_light", "floor_tile_dark",
                               "wood", "roof_slate"}) {
        if (name == n) {
            NAVE_ASSIGN_OR_RETURN(Spectrum albedo, building.ToSpectrum(n));
            return Material(DiffuseMaterial{albedo});
        }
    }
    if (name.rfind("glass_", 0) == 0) {
        const SpectraTable& glass = EmbeddedSpectraTable("stained_glass_approx.csv");
        StatusOr<Spectrum> t = glass.ToSpectrum(name);
        if (t.ok()) return Material(ThinGlassMaterial::FromTotalTransmittance(SodaLimeIndex(), *t));
    }
    // Came lead: oxidised, so a rough conductor rather than a mirror.
    if (name == "lead") return Material(Metal("Pb", 0.35f));
    if (name == "gold") return Material(Metal("Au", 0.f));
    if (name == "silver") return Material(Metal("Ag", 0.f));
    if (name == "copper") return Material(Metal("Cu", 0.f));
    if (name == "aluminium") return Material(Metal("Al", 0.f));
    if (name == "bk7") return Material(DielectricMaterial{Bk7Index(), Spectrum::Constant(0.f)});
    if (name == "glass_grisaille") {
        // A 3 mm pane (the thickness the approximated panes assume, data/SOURCES.md) of measured
        // green soda-lime glass: Fe²⁺/Fe³⁺, the colourant of medieval forest glass, measured
        // (Rubin 1985) rather than approximated like the other glass_ builtins.
        return Material(ThinGlassMaterial::FromAbsorption(
            SodaLimeIndex(), GreenSodaLimeAbsorptionPerMetre(), 0.003));
    }
    if (name == "window_glass") {
        // A 4 mm pane of clear soda-lime glass.
        return Material(ThinGlassMaterial::FromAbsorption(SodaLimeIndex(),
                                                          SodaLimeAbsorptionPerMetre(), 0.004));
    }
    std::string all;
    for (const char* n : kNames) all += (all.empty() ? "" : ", ") + std::string(n);
    return NotFoundError("no built-in material '{}' (known: {})", name, all);
}

}  // namespace nave
