#pragma once
// How the abbey's detail parameter D turns into tessellation. Triangles grow about linearly with D:
// stone faces, slates and tiles are n x n grids with n = round(sqrt(D)) (tooled relief), curves are
// divided into about sqrt(D) times more segments in each direction. Below D = 1 the masonry units
// grow instead (fewer stones), for small test models.

#include <algorithm>
#include <cmath>

namespace nave::preprocess::abbey {

struct Detail {
    double d = 1.0;
    explicit Detail(double detail) : d(detail) {}
    double Root() const { return std::sqrt(d); }
    /// Subdivisions of a stone face, tile or slate.
    int Grid() const { return std::max(1, int(std::lround(Root()))); }
    /// Segments for a curve that has `base` segments at D = 1.
    int Seg(int base) const { return std::max(3, int(std::lround(base * Root()))); }
    /// Scale of masonry units (1 at D >= 1, larger below).
    double UnitScale() const { return d >= 1 ? 1.0 : 1.0 / std::sqrt(std::max(d, 1e-4)); }
};

}  // namespace nave::preprocess::abbey
