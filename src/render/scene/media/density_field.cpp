#include "src/render/scene/media/density_field.h"

#include <utility>

namespace nave::render {

bool ClipToBox(const Bounds3f& box, const Vec3f& o, const Vec3f& d, float t_max, float* t0,
               float* t1) {
    // Slabs (Kay & Kajiya 1986): the ray's parameter interval between each pair of planes,
    // intersected. A direction parallel to a slab's planes gives ±infinity (or NaN on a plane,
    // which the comparisons below leave out).
    float lo = 0, hi = t_max;
    for (int axis = 0; axis < 3; ++axis) {
        const float inv = 1.f / d[axis];
        float near = (box.min[axis] - o[axis]) * inv;
        float far = (box.max[axis] - o[axis]) * inv;
        if (near > far) std::swap(near, far);
        if (near > lo) lo = near;
        if (far < hi) hi = far;
        if (lo > hi) return false;
    }
    *t0 = lo;
    *t1 = hi;
    return hi > lo;
}

}  // namespace nave::render
