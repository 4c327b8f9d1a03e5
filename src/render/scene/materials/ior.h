#pragma once
// Spectral indices of refraction of dielectrics and conductors (nave's glass and metal data).

#include <string_view>

#include "src/core/spectrum.h"
#include "src/core/status.h"

namespace nave {

/// Sellmeier's equation n²(λ) = 1 + Σ B_i λ² / (λ² - C_i), λ in µm, C_i in µm² (Sellmeier 1871).
Spectrum SellmeierIndex(double b1, double b2, double b3, double c1_um2, double c2_um2,
                        double c3_um2);
/// Cauchy's equation n(λ) = A + B / λ² (λ in µm, B in µm²).
Spectrum CauchyIndex(double a, double b_um2);
/// Schott N-BK7 borosilicate crown (Schott optical glass data sheet, Sellmeier coefficients
/// B = 1.03961212, 0.231792344, 1.01046945; C = 0.00600069867, 0.0200179144, 103.560653 µm²).
/// n(587.56 nm) = 1.51680.
const Spectrum& Bk7Index();
/// Clear soda-lime-silica window glass, Rubin (1985) fit n = 1.5130 - 0.003169 λ² + 0.003962 / λ²
/// (µm).
const Spectrum& SodaLimeIndex();
/// The Beer-Lambert absorption coefficient α = 4πk/λ (per metre) of a medium of extinction
/// coefficient `k` (the imaginary part of its index n + ik; Born & Wolf §14.1).
Spectrum AbsorptionPerMetre(const Spectrum& k);
/// Absorption coefficient α = 4πκ/λ (per metre) of clear soda-lime glass from Rubin's κ (1985).
const Spectrum& SodaLimeAbsorptionPerMetre();
/// Absorption coefficient of green (iron-tinted) soda-lime window glass from Rubin's measured k
/// (1985, the same paper's green glass): the nearest published measurement nave has of the
/// greenish, iron-coloured glass of medieval grisaille windows.
const Spectrum& GreenSodaLimeAbsorptionPerMetre();

/// Complex index n + iκ of a metal.
struct ComplexIndex {
    Spectrum eta, k;
};
/// Metals with compiled-in optical constants: "Au" (gold), "Ag" (silver), "Cu" (copper) from
/// Johnson & Christy 1972, "Al" (aluminium) from McPeak et al. 2015, "Pb" (lead) from Werner et al.
/// 2009. Names or symbols, case-insensitive. NotFound lists them.
StatusOr<ComplexIndex> NamedMetal(std::string_view name);

}  // namespace nave
