#pragma once
// Materials: scene-level descriptions that own their spectra and build a Bxdf (bxdf.h) per hit for
// the path's wavelengths. Value types; scene configs map material names to these (see
// BuiltinMaterial for the procedural abbey's names).

#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/render/scene/materials/bxdf.h"

namespace nave {

/// A Lambertian surface of spectral albedo `albedo` (reflectance in [0, 1]).
struct DiffuseMaterial {
    Spectrum albedo = Spectrum::Constant(0.5f);

    Bxdf GetBxdf(SampledWavelengths& lambda) const { return DiffuseBxdf(albedo.Sample(lambda)); }
};

/// A metal: complex index (η, κ), smooth when alpha = 0, else GGX roughness α (anisotropic
/// allowed).
struct ConductorMaterial {
    Spectrum eta = Spectrum::Constant(1.f);
    Spectrum k = Spectrum::Constant(0.f);
    float alpha_x = 0.f, alpha_y = 0.f;

    Bxdf GetBxdf(SampledWavelengths& lambda) const {
        return ConductorBxdf(TrowbridgeReitz(alpha_x, alpha_y), eta.Sample(lambda),
                             k.Sample(lambda));
    }
};

/// A solid dielectric (glass, water): smooth interface of spectral index `eta` and Beer-Lambert
/// absorption inside.
/// Dispersion: when eta varies with λ, GetBxdf terminates the path's secondary wavelengths (only
/// the hero keeps going, refracted at its own index), so prisms split white light into colours.
/// Absorption: the integrator multiplies the throughput of each path segment travelled *inside* by
/// Transmittance(length); the interface itself does not absorb.
struct DielectricMaterial {
    Spectrum eta = Spectrum::Constant(1.5f);
    /// Absorption coefficient α(λ) in m⁻¹ (0: clear).
    Spectrum absorption_per_m = Spectrum::Constant(0.f);
    /// GGX roughness α of the surface (0: polished).
    float alpha = 0.f;

    bool IsDispersive() const { return !eta.IsConstant(); }
    Bxdf GetBxdf(SampledWavelengths& lambda) const {
        if (IsDispersive()) lambda.TerminateSecondary();
        return DielectricBxdf(eta.Evaluate(lambda.lambda_nm(0)), TrowbridgeReitz(alpha, alpha));
    }
    /// exp(-α(λ) d): Beer-Lambert transmittance of `distance_m` of the medium (Beer 1852).
    SampledSpectrum Transmittance(float distance_m, const SampledWavelengths& lambda) const {
        return Exp(absorption_per_m.Sample(lambda) * -distance_m);
    }
};

/// A thin pane (window glass, stained glass): index eta(λ) and the internal transmittance of one
/// pass at normal incidence `internal_transmittance` (so the pane's total transmittance follows
/// from both, with the inter-reflections summed: see ThinDielectricBxdf).
struct ThinGlassMaterial {
    Spectrum eta = Spectrum::Constant(1.5f);
    Spectrum internal_transmittance = Spectrum::Constant(1.f);

    /// A pane `thickness_m` thick of a glass absorbing `absorption_per_metre`: one pass transmits
    /// exp(-α d) (Beer-Lambert); the Fresnel series of its two faces is the BxDF's.
    static ThinGlassMaterial FromAbsorption(const Spectrum& eta,
                                            const Spectrum& absorption_per_metre,
                                            double thickness_m);
    /// The pane whose total normal-incidence transmittance is the measured `total_transmittance`
    /// (what a spectrophotometer reports for a pane): inverts T = (1-R)² τ / (1 - R² τ²) for τ per
    /// wavelength, with R the single-face Fresnel reflectance of eta at normal incidence.
    static ThinGlassMaterial FromTotalTransmittance(const Spectrum& eta,
                                                    const Spectrum& total_transmittance);

    /// The BxDF for a hit. `internal_transmittance_override` is the hook for textures (a
    /// stained-glass window's UV map gives τ per texel): when set, it replaces
    /// internal_transmittance at this hit.
    Bxdf GetBxdf(SampledWavelengths& lambda,
                 const SampledSpectrum* internal_transmittance_override = nullptr) const {
        SampledSpectrum tau = internal_transmittance_override
                                  ? *internal_transmittance_override
                                  : internal_transmittance.Sample(lambda);
        return ThinDielectricBxdf(eta.Sample(lambda), tau);
    }
    /// Per-wavelength inversion used by FromTotalTransmittance (exposed for textures that store
    /// total T).
    static float InternalFromTotalTransmittance(float total_t, float eta);
};

/// Any material.
using Material =
    std::variant<DiffuseMaterial, ConductorMaterial, DielectricMaterial, ThinGlassMaterial>;

/// The BxDF of `m` at a hit (may terminate secondary wavelengths: dispersion).
Bxdf GetBxdf(const Material& m, SampledWavelengths& lambda);

/// Built-in materials by name: the procedural abbey's limestone, limestone_dark, floor_tile_light,
/// floor_tile_dark, glass_clear, glass_blue, glass_red, glass_yellow, glass_green, lead, wood,
/// roof_slate; and gold, silver, copper, aluminium (smooth), bk7 (dispersive crown glass),
/// window_glass (soda-lime pane). NotFound lists the names. Stone, tile, wood and stained-glass
/// spectra are approximations (see data/SOURCES.md).
StatusOr<Material> BuiltinMaterial(std::string_view name);
/// The names BuiltinMaterial accepts.
std::vector<std::string> BuiltinMaterialNames();

}  // namespace nave
