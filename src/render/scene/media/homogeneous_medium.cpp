#include "src/render/scene/media/homogeneous_medium.h"

#include <algorithm>
#include <cmath>

namespace nave::render {

bool HomogeneousMedium::Overlap(const Vec3f& o, const Vec3f& d, float t_max, float* t0,
                                float* t1) const {
    // Slabs (Kay & Kajiya 1986): the ray's parameter interval between each pair of planes,
    // intersected. A direction parallel to a slab's planes gives ±infinity (or NaN on a plane,
    // which the comparisons below leave out).
    float lo = 0, hi = t_max;
    for (int axis = 0; axis < 3; ++axis) {
        const float inv = 1.f / d[axis];
        float near = (box_.min[axis] - o[axis]) * inv;
        float far = (box_.max[axis] - o[axis]) * inv;
        if (near > far) std::swap(near, far);
        if (near > lo) lo = near;
        if (far < hi) hi = far;
        if (lo > hi) return false;
    }
    *t0 = lo;
    *t1 = hi;
    return hi > lo;
}

SampledSpectrum HomogeneousMedium::Transmittance(const Vec3f& o, const Vec3f& d, float t_max,
                                                 const SampledWavelengths& lambda) const {
    const float length = LengthInside(o, d, t_max);
    if (length == 0) return SampledSpectrum(1.f);
    const SampledSpectrum sigma_t = SigmaT(lambda);
    SampledSpectrum t;
    for (int i = 0; i < kNumWavelengths; ++i) t[i] = std::exp(-sigma_t[i] * length);
    return t;
}

}  // namespace nave::render
