#pragma once
// CIE standard illuminants and other named light spectra (relative spectral power distributions).

#include <string_view>

#include "src/core/color.h"
#include "src/core/spectrum.h"
#include "src/core/status.h"

namespace nave {

/// CIE standard illuminant D65 (CIE 15:2004 Table T.1, 5 nm table interpolated linearly to 1 nm, as
/// the CIE's 1 nm table is), 100 at 560 nm.
const Spectrum& IlluminantD65();
/// CIE illuminant D50: the daylight illuminant of CCT 5000 × 1.4388/1.4380 ≈ 5003 K (CIE 15:2004
/// §3.1), 100 at 560 nm.
const Spectrum& IlluminantD50();
/// CIE standard illuminant A, defined by Planck's law at 2856 K with c2 = 1.4388e-2 m K, 100 at 560
/// nm (CIE 15:2004 eq. 3.1).
const Spectrum& IlluminantA();
/// The equal-energy illuminant E (1 everywhere).
const Spectrum& IlluminantE();

/// A light spectrum by name: "D65", "D50", "A", "E", "D<cct>" for a CIE daylight of that CCT in
/// kelvin ("D5500" or "D:5500"), "blackbody:<kelvin>" (peak 1). Case-insensitive. InvalidArgument
/// naming the accepted forms otherwise.
StatusOr<Spectrum> NamedIlluminant(std::string_view name);

/// The chromaticity of an illuminant for the CIE 1931 observer.
Chromaticity IlluminantChromaticity(const Spectrum& illuminant);

}  // namespace nave
