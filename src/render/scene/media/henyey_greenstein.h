#pragma once
// The Henyey-Greenstein phase function (Henyey & Greenstein 1941, "Diffuse radiation in the
// galaxy", ApJ 93, eq. 3): the angular distribution of light scattered in a medium, one parameter g
// (the mean cosine of the scattering angle) from backward (-1) through isotropic (0) to forward
// (1). Angles are between the direction light travelled before the scattering and after it.

#include "src/core/sampling.h"
#include "src/core/vecmath.h"

namespace nave::render {

/// A direction scattered by the phase function, with its density.
struct PhaseSample {
    Vec3f wi;   ///< unit direction the light travels on
    float pdf;  ///< solid-angle density, equal to the phase function's value (it is normalised)
};

class HenyeyGreenstein {
  public:
    /// g in (-1, 1).
    explicit HenyeyGreenstein(float g) : g_(g) {}
    float g() const { return g_; }
    /// The phase function (sr^-1) for the cosine of the scattering angle: it integrates to 1 over
    /// the sphere.
    float Eval(float cos_theta) const;
    /// A direction scattered from `dir` (unit, the direction the light travelled on), sampled
    /// exactly by inverting the distribution of cos θ.
    PhaseSample Sample(const Vec3f& dir, Point2f u) const;

  private:
    float g_;
};

}  // namespace nave::render
