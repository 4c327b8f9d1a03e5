#pragma once
// Paths through a medium (scene/media/medium.h): where a path ray scatters in the medium, and the
// weights that make each outcome (a scattering in the medium, a surface reached, the sky reached)
// an unbiased estimate at every wavelength.
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
//
// A path ray draws, when it starts, the integral D* at which it scatters (FlightDepth), and flies
// brick by brick: in each, it walks the density that brick holds (Medium::DensityIn, a stored
// grid's piece or the medium's own field) from where it entered to the next stop (a surface, the
// next brick, or the end of the model), and scatters where its flight's integral reaches D*. What
// it carries between bricks is that integral so far (RayRecord::flight_depth), so a grid cut into
// bricks is never needed whole, and 1 brick or many give the same flights.

#include <algorithm>
#include <cmath>
#include <limits>

#include "src/core/spectrum.h"
#include "src/render/bricks/density_field.h"
#include "src/render/scene/media/medium.h"
#include "src/render/stream/level_choice.h"
#include "src/render/stream/ray.h"

namespace nave::render {

/// The density's integral from a path ray's origin to where it scatters, sampled with uniform
/// numbers `u_choice` (the wavelength of `lambda` whose σs draws it) and `u_distance`: the inverse
/// of that wavelength's exponential. Infinity when that σs is 0 (the ray does not scatter).
inline float FlightDepth(const Medium& medium, const SampledWavelengths& lambda, float u_choice,
                         float u_distance) {
    const int j = std::min(int(u_choice * kNumWavelengths), kNumWavelengths - 1);
    const float sigma_s = medium.SigmaS(lambda)[j];
    if (!(sigma_s > 0)) return std::numeric_limits<float>::infinity();
    return -std::log1p(-u_distance) / sigma_s;
}

/// Flies path ray `r` over [t0, t1] of its ray through `field` (null: no density there), toward
/// `target` (its FlightDepth): the t at which its flight's integral reaches `target`, where it
/// scatters; else infinity, and r->flight_depth grows by what it crossed.
inline float Fly(const DensityField* field, float target, float t0, float t1, RayRecord* r) {
    constexpr float kNever = std::numeric_limits<float>::infinity();
    if (field == nullptr || !(t1 > t0)) return kNever;
    float walked = 0;
    const float t = field->Walk(r->origin, r->dir, t0, t1, target - r->flight_depth, &walked);
    if (t < kNever) return t;
    r->flight_depth += walked;
    return kNever;
}

/// The weight of a path ray at `lambda` that crossed `depth` of the density's integral without
/// scattering (to a surface, or out of the model): exp(-σt D) over the probability that no
/// scattering was sampled before.
inline SampledSpectrum NoScatterWeight(const Medium& medium, const SampledWavelengths& lambda,
                                       float depth) {
    if (depth == 0) return SampledSpectrum(1.f);
    const SampledSpectrum sigma_t = medium.SigmaT(lambda), sigma_s = medium.SigmaS(lambda);
    SampledSpectrum transmittance;
    float probability = 0;
    for (int i = 0; i < kNumWavelengths; ++i) {
        transmittance[i] = std::exp(-sigma_t[i] * depth);
        probability += std::exp(-sigma_s[i] * depth) / kNumWavelengths;
    }
    return probability > 0 ? transmittance / probability : SampledSpectrum(0.f);
}

/// The weight of a path ray at `lambda` that scatters in the medium `depth` of the density's
/// integral from its origin (its FlightDepth): σs exp(-σt D) over the density with which the
/// scattering was sampled there (the medium's density at the point cancels).
inline SampledSpectrum ScatterWeight(const Medium& medium, const SampledWavelengths& lambda,
                                     float depth) {
    const SampledSpectrum sigma_t = medium.SigmaT(lambda), sigma_s = medium.SigmaS(lambda);
    SampledSpectrum transmittance;
    float density = 0;
    for (int i = 0; i < kNumWavelengths; ++i) {
        transmittance[i] = std::exp(-sigma_t[i] * depth);
        density += sigma_s[i] * std::exp(-sigma_s[i] * depth) / kNumWavelengths;
    }
    return density > 0 ? sigma_s * transmittance / density : SampledSpectrum(0.f);
}

/// The radiance path ray `r` gathers from what `medium` emits (medium_emission.h) over [t0, t1) of
/// its ray in `field`, a flight that entered t0 at `depth0` of the density's integral (its
/// flight_depth there) and did not scatter before t1: a weight for r.beta. The emission term of the
/// radiative transfer equation, ∫ T(s) σa ρ(s) Le(s) ds along the ray, is estimated with the
/// flight's own sampling: the flight reaches s with probability P(s) = mean_j exp(-σs_j D(s)), so
/// counting T(s) / P(s) σa ρ Le = NoScatterWeight(D(s)) σa ρ Le at points the flight crosses is
/// unbiased whatever it does further on, and needs no walk beyond where it scattered. The points
/// are a lattice along the ray, s = (k + u) Δ, shifted by the uniform number `u`: a stratified
/// estimate of the integral, unbiased (Δ Σ_k f((k + u) Δ) has mean ∫ f), and fixed by the ray
/// alone, so that however bricks cut the ray each point is counted once, by the brick whose span
/// holds it: 1 brick or many give the same sum. Δ is the emission grid's voxel (points only in its
/// emitting voxels), or else the density's detail (DensityField::detail_m).
inline SampledSpectrum EmissionAlong(const Medium& medium, const DensityField& field,
                                     const RayRecord& r, float depth0, float t0, float t1,
                                     float u) {
    SampledSpectrum sum(0.f);
    const MediumEmission* emission = medium.emission();
    if (emission == nullptr || !(t1 > t0)) return sum;
    const SampledSpectrum sigma_a = medium.SigmaA(r.lambda);
    if (sigma_a.IsZero()) return sum;
    // Only where there is density: a stretch may run to infinity past the model.
    if (!ClipRayToBounds(field.bounds(), r.origin, r.dir, t0, t1, &t0, &t1)) return sum;
    const volumes::ScalarGrid* grid = emission->grid();
    const double step = grid != nullptr ? grid->voxel_size() : field.detail_m();
    if (!(step > 0)) return sum;
    float s_before = t0, depth = depth0;
    const auto add_points = [&](float a, float b) {
        for (double k = std::ceil(double(a) / step - double(u));; k += 1) {
            const float s = float((k + double(u)) * step);
            if (!(s < b)) break;
            if (s < a) continue;  // rounding
            depth += field.Integral(r.origin, r.dir, s_before, s);
            s_before = s;
            const Vec3f p = r.origin + r.dir * s;
            const float density = field.Density(p);
            if (!(density > 0)) continue;
            sum += NoScatterWeight(medium, r.lambda, depth) * sigma_a *
                   emission->Radiance(p, r.lambda) * (density * float(step));
        }
    };
    if (grid != nullptr) {
        grid->March(r.origin, r.dir, t0, t1, [&](float a, float b, float value) {
            if (value > 0) add_points(a, b);
            return true;
        });
    } else {
        add_points(t0, t1);
    }
    return sum;
}

/// Path or photon `r` reaching a surface without scattering in `medium` (null: none): its weight
/// for the flight (NoScatterWeight), and what goes on from the surface is a new flight.
inline void EndFlightAtSurface(const Medium* medium, RayRecord* r) {
    if (medium == nullptr) return;
    r->beta *= NoScatterWeight(*medium, r->lambda, r->flight_depth);
    r->flight_depth = 0;
}

/// Dims shadow ray `r` by what `medium` (null: none) lets through over [t0, t1] of its ray while it
/// is processed in `brick` (null: outside every brick; Medium::DensityIn). False if nothing is
/// left of it.
inline bool DimShadowRay(const Medium* medium, const ResidentBrick* brick, float t0, float t1,
                         RayRecord* r) {
    if (medium == nullptr) return true;
    const DensityField* field = medium->DensityIn(brick);
    if (field == nullptr) return true;
    r->beta *= medium->Transmittance(field->Integral(r->origin, r->dir, t0, t1), r->lambda);
    return !r->beta.IsZero();
}

/// Moves path or photon `r`, which scatters in the medium at t = `t` of its ray, on toward `wi`
/// (sampled from the phase function): its next vertex and a new flight. A scattering widens the
/// ray's cone as a diffuse bounce does, and leaves no surface level behind.
inline void LeaveMediumVertex(RayRecord* r, float t, const Vec3f& wi) {
    r->vertex += 1;
    r->depth += 1;
    r->flags &= uint8_t(~kSpecularBounce);
    r->cone_width = ConeWidthAt(*r, t);
    r->cone_spread = std::max(r->cone_spread, kScatteredConeSpread);
    r->origin_level = 0;
    r->level_reach = 0;
    r->origin = r->origin + r->dir * t;
    r->since_vertex = 0;
    r->dir = wi;
    r->t_max = std::numeric_limits<float>::infinity();
    r->t_enter = r->t_exit = 0;
    r->flight_depth = 0;
}

}  // namespace nave::render
