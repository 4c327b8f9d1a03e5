#pragma once
// Paths through a medium (scene/media/medium.h): where a path ray scatters
// in the medium, sampled when the ray starts, and the weights that make each outcome (a scattering
// in the medium, a surface reached, the sky reached) an unbiased estimate at every wavelength.
//
// The distance to a scattering is drawn from the scattering coefficient σs alone and absorption is
// carried as a weight, exp(-σa ℓ): survival biasing (Spanier & Gelbard 1969, "Monte Carlo
// Principles and Neutron Transport Problems", §4.4), so no path ends in the medium by chance and a
// purely absorbing one dims what is behind it without noise. The distance comes from one
// wavelength's exponential, the wavelength chosen uniformly among the path's: the one-sample
// balance heuristic over wavelengths (Wilkie et al. 2014, "Hero wavelength spectral sampling",
// EGSR; Miller, Georgiev & Jarosz 2019, "A null-scattering path integral formulation of light
// transport", §5.3), so coefficients that vary with wavelength cost no colour noise. Under that
// mixture the density of a scattering at t, where the medium's density is ρ and its integral from
// the ray's origin is D, is ρ mean_j σs_j exp(-σs_j D), and the probability of none before it is
// mean_j exp(-σs_j D): ρ cancels in every weight, which therefore needs only D (the length inside
// a homogeneous medium's box; an exact sum over voxels for a grid).

#include <algorithm>
#include <cmath>

#include "src/core/spectrum.h"
#include "src/render/scene/media/medium.h"
#include "src/render/stream/ray.h"

namespace nave::render {

/// The density's integral from a path ray's origin to where it scatters, sampled with uniform
/// numbers `u_choice` (the wavelength of `lambda` whose σs draws it) and `u_distance`: the inverse
/// of that wavelength's exponential. 0 when that σs is 0 (the ray does not scatter).
inline float FlightDepth(const Medium& medium, const SampledWavelengths& lambda, float u_choice,
                         float u_distance) {
    const int j = std::min(int(u_choice * kNumWavelengths), kNumWavelengths - 1);
    const float sigma_s = medium.SigmaS(lambda)[j];
    if (!(sigma_s > 0)) return 0.f;
    return -std::log1p(-u_distance) / sigma_s;
}

/// Samples where path ray `r` (from its origin, up to its t_max) scatters in `medium`: where the
/// density's integral reaches `depth` (FlightDepth). If before t_max, sets t_max there and
/// kMediumScatter; else leaves the ray as it is.
inline void StartFlight(const Medium& medium, float depth, RayRecord* r) {
    r->flags &= uint8_t(~kMediumScatter);
    if (!(depth > 0)) return;
    const float t = medium.density().Reach(r->origin, r->dir, r->t_max, depth);
    if (!(t < r->t_max)) return;
    r->t_max = t;
    r->flags |= kMediumScatter;
}

/// The weight of path ray `r` that reached t = `t_end` (a surface, or infinity: out of the model)
/// without scattering in `medium`: exp(-σt D) over the probability that no scattering was sampled
/// before, D the density's integral up to t_end.
inline SampledSpectrum NoScatterWeight(const Medium& medium, const RayRecord& r, float t_end) {
    const float depth = medium.density().Integral(r.origin, r.dir, t_end);
    if (depth == 0) return SampledSpectrum(1.f);
    const SampledSpectrum sigma_t = medium.SigmaT(r.lambda), sigma_s = medium.SigmaS(r.lambda);
    SampledSpectrum transmittance;
    float probability = 0;
    for (int i = 0; i < kNumWavelengths; ++i) {
        transmittance[i] = std::exp(-sigma_t[i] * depth);
        probability += std::exp(-sigma_s[i] * depth) / kNumWavelengths;
    }
    return probability > 0 ? transmittance / probability : SampledSpectrum(0.f);
}

/// The weight of path ray `r` that scatters in `medium` at its t_max (kMediumScatter), `depth` of
/// the density's integral from its origin (the FlightDepth that StartFlight reached): σs exp(-σt D)
/// over the density with which the scattering was sampled there (the medium's density at the point
/// cancels).
inline SampledSpectrum ScatterWeight(const Medium& medium, const RayRecord& r, float depth) {
    const SampledSpectrum sigma_t = medium.SigmaT(r.lambda), sigma_s = medium.SigmaS(r.lambda);
    SampledSpectrum transmittance;
    float density = 0;
    for (int i = 0; i < kNumWavelengths; ++i) {
        transmittance[i] = std::exp(-sigma_t[i] * depth);
        density += sigma_s[i] * std::exp(-sigma_s[i] * depth) / kNumWavelengths;
    }
    return density > 0 ? sigma_s * transmittance / density : SampledSpectrum(0.f);
}

}  // namespace nave::render
