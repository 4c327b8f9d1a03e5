#pragma once
// Small vector and box types shared by the store, preprocess and render. Header-only and
// dependency-free.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <ostream>
#include <utility>

namespace nave {

template <typename T>
struct Vec3 {
    T x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <typename U>
    constexpr explicit Vec3(const Vec3<U>& v) : x(T(v.x)), y(T(v.y)), z(T(v.z)) {}

    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }
    constexpr Vec3& operator+=(const Vec3& o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    constexpr Vec3& operator-=(const Vec3& o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    constexpr Vec3& operator*=(T s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    constexpr bool operator==(const Vec3& o) const = default;
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
using Vec3i = Vec3<int32_t>;

template <typename T>
constexpr Vec3<T> operator*(T s, const Vec3<T>& v) {
    return v * s;
}
template <typename T>
constexpr T Dot(const Vec3<T>& a, const Vec3<T>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T>
constexpr Vec3<T> Cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T>
T Length(const Vec3<T>& v) {
    return std::sqrt(Dot(v, v));
}
template <typename T>
Vec3<T> Normalize(const Vec3<T>& v) {
    return v / Length(v);
}
template <typename T>
constexpr Vec3<T> Min(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T>
constexpr Vec3<T> Max(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T>
bool IsFinite(const Vec3<T>& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
template <typename T>
std::ostream& operator<<(std::ostream& os, const Vec3<T>& v) {
    return os << "(" << v.x << ", " << v.y << ", " << v.z << ")";
}

/// An axis-aligned box. A default-constructed box is empty (min > max) and absorbs the first point
/// added.
template <typename T>
struct Bounds3 {
    Vec3<T> min{std::numeric_limits<T>::max(), std::numeric_limits<T>::max(),
                std::numeric_limits<T>::max()};
    Vec3<T> max{std::numeric_limits<T>::lowest(), std::numeric_limits<T>::lowest(),
                std::numeric_limits<T>::lowest()};

    constexpr Bounds3() = default;
    constexpr Bounds3(const Vec3<T>& lo, const Vec3<T>& hi) : min(lo), max(hi) {}

    constexpr bool Empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    constexpr void Extend(const Vec3<T>& p) {
        min = Min(min, p);
        max = Max(max, p);
    }
    constexpr void Extend(const Bounds3& b) {
        min = Min(min, b.min);
        max = Max(max, b.max);
    }
    constexpr Vec3<T> Diagonal() const { return max - min; }
    constexpr Vec3<T> Center() const { return (min + max) * T(0.5); }
    constexpr bool Contains(const Vec3<T>& p) const {
        return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z &&
               p.z <= max.z;
    }
    constexpr bool Overlaps(const Bounds3& b) const {
        return min.x <= b.max.x && max.x >= b.min.x && min.y <= b.max.y && max.y >= b.min.y &&
               min.z <= b.max.z && max.z >= b.min.z;
    }
    /// The axis (0, 1, 2) along which the box is longest.
    constexpr int MaxAxis() const {
        Vec3<T> d = Diagonal();
        return (d.x >= d.y && d.x >= d.z) ? 0 : (d.y >= d.z ? 1 : 2);
    }
    constexpr bool operator==(const Bounds3& o) const = default;
};

using Bounds3f = Bounds3<float>;
using Bounds3d = Bounds3<double>;

/// Where the ray o + t d, t in [t_min, t_max], crosses `box`: [*t0, *t1] (possibly a single
/// point); false when it misses. Slabs (Kay & Kajiya 1986): the ray's parameter interval between
/// each pair of planes, intersected. An axis the ray runs along while lying on one of its planes
/// gives NaN and is left out.
inline bool ClipRayToBounds(const Bounds3f& box, const Vec3f& o, const Vec3f& d, float t_min,
                            float t_max, float* t0, float* t1) {
    float lo = t_min, hi = t_max;
    for (int a = 0; a < 3; ++a) {
        const float inv = 1.0f / d[a];
        float near = (box.min[a] - o[a]) * inv;
        float far = (box.max[a] - o[a]) * inv;
        if (near > far) std::swap(near, far);
        if (!(near <= far)) continue;  // NaN
        lo = std::max(lo, near);
        hi = std::min(hi, far);
        if (lo > hi) return false;
    }
    *t0 = lo;
    *t1 = hi;
    return true;
}

template <typename T>
std::ostream& operator<<(std::ostream& os, const Bounds3<T>& b) {
    return os << "[" << b.min << " - " << b.max << "]";
}

}  // namespace nave
