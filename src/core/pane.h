#pragma once
// A pane of glass seen as a slab with two identical faces: its measured total transmittance and the
// internal transmittance of one pass through it.

#include <algorithm>
#include <cmath>

namespace nave {

/// The internal transmittance τ of one pass through a pane whose total normal-incidence
/// transmittance (what a spectrophotometer reports) is `total_t`, each face reflecting
/// `face_reflectance` R: the pane with multiple reflections between its faces transmits T = (1-R)²
/// τ / (1 - R² τ²) (e.g. Born & Wolf, Principles of Optics, incoherent slab), solved for the
/// positive root of R² T τ² + (1-R)² τ - T = 0. A total above what a lossless pane allows, (1 - R)
/// / (1 + R), gives 1. In [0, 1].
inline float PaneInternalTransmittance(float total_t, double face_reflectance) {
    const double r = face_reflectance;
    const double t = std::clamp(double(total_t), 0.0, 1.0);
    const double one_r2 = (1.0 - r) * (1.0 - r);
    if (t >= (1.0 - r) / (1.0 + r)) return 1.f;
    if (r == 0.0) return float(t);
    const double a = r * r * t;
    if (a == 0.0) return 0.f;
    const double tau = (-one_r2 + std::sqrt(one_r2 * one_r2 + 4.0 * a * t)) / (2.0 * a);
    return float(std::clamp(tau, 0.0, 1.0));
}

}  // namespace nave
