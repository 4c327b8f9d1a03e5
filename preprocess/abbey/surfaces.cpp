#include "preprocess/abbey/surfaces.h"

#include <algorithm>
#include <cmath>

#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"

namespace nave::preprocess::abbey {

void EmitTiledFloor(Emitter& em, double x0, double x1, double y0, double y1,
                    const std::function<bool(double, double)>& inside, const Detail& detail) {
    const double tile = 0.5 * detail.UnitScale();
    StoneStyle style;
    style.joint = 0.004;
    style.relief = 0.015;
    style.chamfer = 0.006;
    style.tooling = 0.0008;
    style.subdivisions = detail.Grid();
    int nx = int(std::ceil((x1 - x0) / tile)), ny = int(std::ceil((y1 - y0) / tile));
    for (int j = 0; j < ny; ++j) {
        // The bedding under this row: one strip per run of tiles inside the plan.
        int run_start = -1;
        for (int i = 0; i <= nx; ++i) {
            double cx = x0 + (i + 0.5) * tile, cy = y0 + (j + 0.5) * tile;
            bool in = i < nx && inside(cx, cy);
            if (in) {
                Frame f{Vec3d(x0 + i * tile, y0 + j * tile, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0),
                        Vec3d(0, 0, 1)};
                uint32_t m = ((i + j) % 2 == 0) ? kFloorLight : kFloorDark;
                Stone(em, f, tile, tile, style, uint64_t(j) * 100003 + uint64_t(i), m);
                if (run_start < 0) run_start = i;
            } else if (run_start >= 0) {
                double a = x0 + run_start * tile, b = x0 + i * tile, c = y0 + j * tile,
                       d = c + tile;
                em.Quad(Vec3d(a, c, 0), Vec3d(b, c, 0), Vec3d(b, d, 0), Vec3d(a, d, 0),
                        Vec3d(0, 0, 1), kFloorDark);
                run_start = -1;
            }
        }
    }
}

void EmitSlateRoof(Emitter& em, const std::function<Vec3d(double, double)>& roof, double length_s,
                   double length_t, const std::function<Vec3d(const Vec3d&)>& up,
                   const Detail& detail, uint64_t seed) {
    const double scale = detail.UnitScale();
    const double row = 0.24 * scale, width = 0.32 * scale, lift = 0.012, thick = 0.01;
    int rows = std::max(1, int(std::ceil(length_t / row)));
    int cols = std::max(1, int(std::ceil(length_s / width)));
    int n = detail.Grid();
    auto normal = [&](double s, double t) {
        const double e = 1e-3;
        Vec3d a = roof(std::min(1.0, s + e), t) - roof(std::max(0.0, s - e), t);
        Vec3d b = roof(s, std::min(1.0, t + e)) - roof(s, std::max(0.0, t - e));
        Vec3d nn = Cross(a, b);
        Vec3d p = roof(s, t);
        if (Dot(nn, up(p)) < 0) nn = -nn;
        double len = Length(nn);
        return len > 0 ? nn / len : Vec3d(0, 0, 1);
    };
    // Sealing deck under the slates.
    int deck = std::max(2, detail.Seg(4));
    ParamGrid(em, roof, deck, deck, up, kRoofSlate);
    for (int r = 0; r < rows; ++r) {
        double t0 = double(r) / rows,
               t1 = std::min(1.0, (r + 1.4) / rows);  // slates overlap the row above
        double offset = (r % 2) * 0.5;
        for (int c = 0; c <= cols; ++c) {
            double s0 = (c - offset) / cols + 0.002, s1 = (c + 1 - offset) / cols - 0.002;
            s0 = std::max(0.0, s0);
            s1 = std::min(1.0, s1);
            if (s1 - s0 < 0.2 / cols) continue;
            // The slate plate: its lower edge lifted (it lies on the row below), tooled like a
            // stone.
            auto at = [&](int i, int k) {
                double s = s0 + (s1 - s0) * i / n, t = t0 + (t1 - t0) * k / n;
                double h = lift * (1.0 - double(k) / n) + thick;
                if (i > 0 && i < n && k > 0 && k < n)
                    h += 0.002 * (2 * Hash01(seed, r * 7919 + c, i * 131 + k) - 1);
                return roof(s, t) + normal(s, t) * h;
            };
            Vec3d out = normal(0.5 * (s0 + s1), 0.5 * (t0 + t1));
            for (int k = 0; k < n; ++k) {
                for (int i = 0; i < n; ++i)
                    em.Quad(at(i, k), at(i + 1, k), at(i + 1, k + 1), at(i, k + 1), out,
                            kRoofSlate);
            }
            // The slate's visible lower edge.
            Vec3d down =
                roof(0.5 * (s0 + s1), t0) - roof(0.5 * (s0 + s1), std::min(1.0, t0 + 0.01));
            for (int i = 0; i < n; ++i) {
                double sa = s0 + (s1 - s0) * i / n, sb = s0 + (s1 - s0) * (i + 1) / n;
                Vec3d a = roof(sa, t0) + normal(sa, t0) * thick * 0.2,
                      b = roof(sb, t0) + normal(sb, t0) * thick * 0.2;
                em.Quad(a, b, at(i + 1, 0), at(i, 0), down, kRoofSlate);
            }
        }
    }
}

}  // namespace nave::preprocess::abbey
