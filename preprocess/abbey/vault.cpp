#include "preprocess/abbey/vault.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"

namespace nave::preprocess::abbey {
namespace {

constexpr double kRho = 2.0;  // equilateral pointed profile
constexpr double kPi = std::numbers::pi;

Vec3d Plan(const VaultBay& b, double u, double v) {
    double s = (u + 1) * 0.5, t = (v + 1) * 0.5;
    return b.corners[0] * ((1 - s) * (1 - t)) + b.corners[1] * (s * (1 - t)) +
           b.corners[2] * (s * t) + b.corners[3] * ((1 - s) * t);
}

Vec3d Intrados(const VaultBay& b, double u, double v) {
    Vec3d p = Plan(b, u, v);
    double m = std::min(std::abs(u), std::abs(v));
    return Vec3d(p.x, p.y, b.spring + b.rise * PointedArch(m, kRho));
}

// The rib section: a pointed roll hanging below the surface (n < 0 is below).
std::vector<Vec2> RibProfile(double half_width, double depth, int n) {
    std::vector<Vec2> p;
    for (int i = 0; i < n; ++i) {
        double a = 2 * kPi * i / n;
        double x = half_width * std::cos(a), y = std::sin(a);
        p.push_back({x, y > 0 ? 0.04 * y : depth * y * (1 - 0.25 * std::abs(x) / half_width)});
    }
    return p;
}

void Rib(Emitter& em, const std::vector<Vec3d>& path, double half_width, double depth,
         const Detail& detail) {
    // Side vector: horizontal, perpendicular to the rib's plan direction, oriented so that the
    // profile's n axis points up at the crown (see Sweep).
    Vec3d d = path.back() - path.front();
    d.z = 0;
    Vec3d side = Normalize(Cross(d, Vec3d(0, 0, 1)));
    Sweep(em, path, side, RibProfile(half_width, depth, detail.Seg(8)), kLimestoneDark);
}

void Boss(Emitter& em, const Vec3d& at, const Detail& detail) {
    std::vector<Vec2> p;
    int n = detail.Seg(6);
    for (int i = 0; i <= n; ++i) {
        double a = kPi / 2 * i / n;
        p.push_back({0.28 * std::sin(a), -0.25 * std::cos(a)});
    }
    p.push_back({0, 0.02});
    Revolve(em, at, p, detail.Seg(16), kLimestoneDark);
}

}  // namespace

void EmitVaultBay(Emitter& em, const VaultBay& b, const Detail& detail) {
    int n = detail.Seg(10);
    Vec3d center = Plan(b, 0, 0);
    Vec3d axis(center.x, center.y, b.spring);
    const double corner_uv[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; ++k) {
        const double* a = corner_uv[k];
        const double* c = corner_uv[(k + 1) % 4];
        // Severy k: the triangle (centre, corner k, corner k+1), s from the centre out, t along the
        // edge.
        auto intrados = [&](double s, double t) {
            double u = s * (a[0] + (c[0] - a[0]) * t), v = s * (a[1] + (c[1] - a[1]) * t);
            return Intrados(b, u, v);
        };
        ParamGrid(
            em, intrados, n, n, [&](const Vec3d& p) { return axis - p; }, kLimestone);
        // The extrados as finely divided as the intrados: coarser chords would sag below it.
        auto extrados = [&](double s, double t) {
            return intrados(s, t) + Vec3d(0, 0, b.thickness);
        };
        ParamGrid(
            em, extrados, n, n, [&](const Vec3d& p) { return p - axis; }, kLimestone);
    }
    // Diagonal ribs along u = v and u = -v, transverse arches along u = -1 / +1.
    int m = detail.Seg(24);
    for (int diag = 0; diag < 2; ++diag) {
        std::vector<Vec3d> path;
        for (int i = 0; i <= m; ++i) {
            double t = -1 + 2.0 * i / m;
            path.push_back(Intrados(b, t, diag == 0 ? t : -t));
        }
        Rib(em, path, 0.13, 0.30, detail);
    }
    for (int side = 0; side < 2; ++side) {
        if ((side == 0 && !b.rib_u_min) || (side == 1 && !b.rib_u_max)) continue;
        double u = side == 0 ? -1 : 1;
        std::vector<Vec3d> path;
        for (int i = 0; i <= m; ++i) path.push_back(Intrados(b, u, -1 + 2.0 * i / m));
        Rib(em, path, 0.22, 0.40, detail);
    }
    Boss(em, Intrados(b, 0, 0), detail);
}

void EmitHalfDome(Emitter& em, const Vec3d& c, const Vec3d& axis, double radius, double spring,
                  double rise, int ribs, const Detail& detail, const Lunette& lunette) {
    Vec3d side =
        Cross(Vec3d(0, 0, 1), axis);  // the half circle runs from -side through axis to +side
    auto plan = [&](double angle) { return side * -std::cos(angle) + axis * std::sin(angle); };
    int sectors = ribs + 1;
    auto point = [&](double s, double angle) {
        Vec3d p = c + plan(angle) * (radius * s);
        double z = spring + rise * PointedArch(s, kRho);
        if (lunette.half_width > 0) {
            // Distance across from the centre line of this point's sector, in metres.
            double sector = kPi / sectors;
            double off = angle - sector * (std::floor(angle / sector) + 0.5);
            double across = radius * s * std::abs(std::sin(off));
            double lift =
                spring + (lunette.crown - spring) * PointedArch(across / lunette.half_width, kRho) -
                z;
            double fade = std::clamp((s - lunette.fade_from) / (1 - lunette.fade_from), 0.0, 1.0);
            z += fade * std::max(0.0, lift);
        }
        return Vec3d(p.x, p.y, z);
    };
    Vec3d centre(c.x, c.y, spring);
    int n = detail.Seg(10);
    for (int k = 0; k < sectors; ++k) {
        double a0 = kPi * k / sectors, a1 = kPi * (k + 1) / sectors;
        // Just inside the sector, so that its edges (on the ribs) take this sector's lunette.
        auto intrados = [&](double s, double t) {
            return point(s, a0 + (a1 - a0) * std::clamp(t, 1e-9, 1 - 1e-9));
        };
        ParamGrid(
            em, intrados, n, n, [&](const Vec3d& p) { return centre - p; }, kLimestone);
        auto extrados = [&](double s, double t) { return intrados(s, t) + Vec3d(0, 0, 0.3); };
        ParamGrid(
            em, extrados, n, n, [&](const Vec3d& p) { return p - centre; }, kLimestone);
    }
    int m = detail.Seg(16);
    for (int k = 1; k <= ribs; ++k) {
        double a = kPi * k / sectors;
        std::vector<Vec3d> path;
        for (int i = m; i >= 0; --i) path.push_back(point(double(i) / m, a));
        Rib(em, path, 0.12, 0.28, detail);  // from the springing up to the crown
    }
    Boss(em, point(0, 0), detail);
}

}  // namespace nave::preprocess::abbey
