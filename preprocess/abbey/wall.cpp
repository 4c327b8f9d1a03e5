#include "preprocess/abbey/wall.h"

#include <algorithm>
#include <cmath>

#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"

namespace nave::preprocess::abbey {

double Opening::Top(double u) const {
    return spring + rise * PointedArch(std::abs(u - center) / half_width, rho);
}

double Opening::HalfWidthAt(double z) const {
    if (z <= spring) return half_width;
    double y = (z - spring) / rise;  // fraction of the rise
    if (y >= 1) return 0;
    // Inverse of PointedArch: (t + rho - 1)^2 = rho^2 - y^2 (2 rho - 1).
    double t = std::sqrt(std::max(0.0, rho * rho - y * y * (2 * rho - 1))) - rho + 1;
    return half_width * std::clamp(t, 0.0, 1.0);
}

Opening Opening::AtFace(bool inner) const {
    Opening o = *this;
    double scale = (half_width + splay) / half_width;
    o.half_width *= scale;
    o.rise *= scale;
    o.splay = 0;
    if (inner) o.sill -= glacis;
    o.glacis = 0;
    return o;
}

namespace {

constexpr Vec3d kUp(0, 0, 1);

struct WallGeom {
    const WallSpec& w;
    Vec3d P(double u, double z, double depth) const {
        return w.origin + w.along * u + kUp * z - w.inward * depth;
    }
};

// Samples of an opening's arch from one springing to the other.
std::vector<double> ArchSamples(const Opening& o, int segments) {
    std::vector<double> xs;
    for (int i = 0; i <= segments; ++i)
        xs.push_back(o.center - o.half_width + 2 * o.half_width * i / segments);
    return xs;
}

void EmitFace(Emitter& em, const WallGeom& g, double depth, const Vec3d& out, int arch_segments) {
    const WallSpec& w = g.w;
    double cursor = 0;
    auto rect = [&](double u0, double u1, double z0, double z1) {
        if (u1 - u0 <= 1e-9 || z1 - z0 <= 1e-9) return;
        em.Quad(g.P(u0, z0, depth), g.P(u1, z0, depth), g.P(u1, z1, depth), g.P(u0, z1, depth), out,
                w.material);
    };
    for (const Opening& in_glass : w.openings) {
        Opening o = in_glass.AtFace(depth == 0);
        double a = o.center - o.half_width, b = o.center + o.half_width;
        rect(cursor, a, w.z0, w.z1);
        rect(a, b, w.z0, o.sill);
        std::vector<double> xs = ArchSamples(o, arch_segments);
        for (size_t i = 0; i + 1 < xs.size(); ++i) {
            double t0 = o.Top(xs[i]), t1 = o.Top(xs[i + 1]);
            em.Quad(g.P(xs[i], t0, depth), g.P(xs[i + 1], t1, depth), g.P(xs[i + 1], w.z1, depth),
                    g.P(xs[i], w.z1, depth), out, w.material);
        }
        cursor = b;
    }
    rect(cursor, w.length, w.z0, w.z1);
}

// The opening's outline (sill, jambs, arch) scaled by `k` round the centre of its springing line:
// the outline at a depth of a splayed window.
// Below the springing the outline is stretched so that the sill falls by `drop` (the glacis).
Vec3d OutlinePoint(const WallGeom& g, const Opening& o, double u, double z, double k, double drop,
                   double depth) {
    double zk = z;
    if (z > o.spring) {
        zk = o.spring + (z - o.spring) * k;
    } else if (drop > 0) {  // (a window with a glacis has its sill below its springing)
        zk = o.spring - (o.spring - z) * (o.spring - o.sill + drop) / (o.spring - o.sill);
    }
    return g.P(o.center + (u - o.center) * k, zk, depth);
}

// The reveals through the thickness: straight, or for a splayed window two bands, from each face
// (outline scaled by AtFace) to the glass plane in the middle (the opening itself).
void EmitReveals(Emitter& em, const WallGeom& g, const Opening& o, int arch_segments) {
    const WallSpec& w = g.w;
    double a = o.center - o.half_width, b = o.center + o.half_width, t = w.thickness;
    double face_k = o.splay > 0 ? (o.half_width + o.splay) / o.half_width : 1.0;
    auto band = [&](double d0, double k0, double drop0, double d1, double k1) {
        auto through = [&](double u0, double z0, double u1, double z1, const Vec3d& out) {
            em.Quad(OutlinePoint(g, o, u0, z0, k0, drop0, d0),
                    OutlinePoint(g, o, u1, z1, k0, drop0, d0),
                    OutlinePoint(g, o, u1, z1, k1, 0, d1), OutlinePoint(g, o, u0, z0, k1, 0, d1),
                    out, w.material);
        };
        if (o.sill > w.z0) through(a, o.sill, b, o.sill, kUp);
        through(a, o.sill, a, o.spring, w.along);
        through(b, o.sill, b, o.spring, -w.along);
        std::vector<double> xs = ArchSamples(o, arch_segments);
        for (size_t i = 0; i + 1 < xs.size(); ++i) {
            double z0 = o.Top(xs[i]), z1 = o.Top(xs[i + 1]);
            Vec3d mid = g.P(0.5 * (xs[i] + xs[i + 1]), 0.5 * (z0 + z1), 0);
            Vec3d axis = g.P(o.center, o.spring, 0);
            through(xs[i], z0, xs[i + 1], z1, axis - mid);
        }
    };
    if (face_k == 1.0 && o.glacis <= 0) {
        band(0, 1, 0, t, 1);
    } else {
        band(0, face_k, o.glacis, t * 0.5, 1);
        band(t, face_k, 0, t * 0.5, 1);
    }
}

void EmitMoulding(Emitter& em, const WallGeom& g, const Opening& o, double depth, const Vec3d& out,
                  const Detail& detail) {
    std::vector<Vec3d> path;
    double a = o.center - o.half_width, b = o.center + o.half_width;
    double bottom = std::max(o.sill, g.w.z0);
    path.push_back(g.P(a, bottom, depth));
    for (double x : ArchSamples(o, detail.Seg(12))) path.push_back(g.P(x, o.Top(x), depth));
    path.push_back(g.P(b, bottom, depth));
    // The roll stands half out of the face, centred on the arris.
    Sweep(em, path, out, CircleProfile(0.07, detail.Seg(6), 0.0), kLimestoneDark);
}

void EmitGlazing(Emitter& em, const WallGeom& g, const Opening& o, const Detail& detail,
                 uint64_t seed) {
    const WallSpec& w = g.w;
    double mid = w.thickness * 0.5;
    double piece = 0.45 / std::pow(std::max(detail.d, 1.0), 0.25);
    double a = o.center - o.half_width, b = o.center + o.half_width;
    double apex = o.spring + o.rise;
    int cols = std::max(2, int(std::lround((b - a) / piece)));
    int rows = std::max(2, int(std::lround((apex - o.sill) / (piece * 1.3))));
    double dx = (b - a) / cols, dz = (apex - o.sill) / rows;
    const uint32_t palette[] = {kGlassClear, kGlassClear, kGlassClear,  kGlassBlue,  kGlassBlue,
                                kGlassRed,   kGlassRed,   kGlassYellow, kGlassGreen, kGlassClear};
    for (int r = 0; r < rows; ++r) {
        double z0 = o.sill + r * dz, z1 = z0 + dz;
        for (int c = 0; c < cols; ++c) {
            double x0 = a + c * dx, x1 = x0 + dx;
            double t0 = std::min(z1, o.Top(x0)), t1 = std::min(z1, o.Top(x1));
            if (t0 <= z0 + 1e-6 && t1 <= z0 + 1e-6) continue;
            t0 = std::max(t0, z0);
            t1 = std::max(t1, z0);
            uint32_t m = palette[int(Hash01(seed, r, c) * 10) % 10];
            // One sheet per pane, facing outward: the renderer's thin-pane material accounts for
            // both faces of the glass in a single surface, so a closed slab would count them twice.
            // Texture coordinates span the whole window, origin top-left (glass_textures.h), so the
            // spectral transmittance map of each glass colour lies across the window.
            auto uv = [&](double x, double z) {
                return std::array<float, 2>{float((x - a) / (b - a)),
                                            float((apex - z) / (apex - o.sill))};
            };
            em.QuadUv(g.P(x0, z0, mid), g.P(x1, z0, mid), g.P(x1, t1, mid), g.P(x0, t0, mid),
                      {uv(x0, z0), uv(x1, z0), uv(x1, t1), uv(x0, t0)}, -w.inward, m);
        }
    }
    // Lead cames on every line between pieces: 12 mm wide, 20 mm deep boxes.
    const double kHalfWidth = 0.006, kHalfDepth = 0.010;
    Vec3d side = w.along * kHalfWidth, depth = w.inward * kHalfDepth;
    for (int c = 1; c < cols; ++c) {
        double x = a + c * dx, top = o.Top(x);
        Vec3d lo = g.P(x, o.sill, mid), hi = g.P(x, top, mid);
        OrientedBox(em, (lo + hi) * 0.5, side, depth, (hi - lo) * 0.5, kLead);
    }
    for (int r = 1; r < rows; ++r) {
        double z = o.sill + r * dz, hw = o.HalfWidthAt(z);
        if (hw < 0.02) continue;
        Vec3d lo = g.P(o.center - hw, z, mid), hi = g.P(o.center + hw, z, mid);
        OrientedBox(em, (lo + hi) * 0.5, (hi - lo) * 0.5, depth, kUp * kHalfWidth, kLead);
    }
}

void EmitDoor(Emitter& em, const WallGeom& g, const Opening& o, const Detail& detail) {
    const WallSpec& w = g.w;
    const double kPlank = 0.16, kHalfThick = 0.04;
    double a = o.center - o.half_width;
    int planks = std::max(2, int(std::lround(2 * o.half_width / kPlank)));
    double pw = 2 * o.half_width / planks;
    double depth = w.thickness * 0.7;
    for (int i = 0; i < planks; ++i) {
        double x0 = a + i * pw + 0.003, x1 = a + (i + 1) * pw - 0.003;
        double top = std::min(o.Top(x0), o.Top(x1)) - 0.005;
        Vec3d lo = g.P(x0, o.sill, depth), hi = g.P(x1, top, depth);
        OrientedBox(em, (lo + hi) * 0.5, w.along * ((x1 - x0) * 0.5), w.inward * kHalfThick,
                    kUp * ((top - o.sill) * 0.5), kWood);
    }
    // Iron-free ledges: three horizontal battens on the inner side.
    for (double f : {0.2, 0.5, 0.8}) {
        double z = o.sill + (o.spring - o.sill) * f;
        Vec3d c = g.P(o.center, z, depth - kHalfThick - 0.03);
        OrientedBox(em, c, w.along * (o.half_width - 0.05), w.inward * 0.03, kUp * 0.08, kWood);
    }
    (void)detail;
}

bool StoneHitsOpening(const WallSpec& w, double u0, double u1, double z0, double z1) {
    const double kMargin = 0.02;
    for (const Opening& in_glass : w.openings) {
        Opening o = in_glass.AtFace(true);  // the larger outline: both faces' stones clear it
        double a = o.center - o.half_width - kMargin, b = o.center + o.half_width + kMargin;
        double top = o.spring + o.rise + kMargin;
        if (u1 > a && u0 < b && z1 > o.sill - kMargin && z0 < top) return true;
    }
    return false;
}

void EmitStones(Emitter& em, const WallGeom& g, double depth, const Vec3d& out,
                const Detail& detail, uint64_t seed) {
    const WallSpec& w = g.w;
    double scale = detail.UnitScale();
    double course = 0.34 * scale, unit = 0.62 * scale;
    StoneStyle style;
    style.subdivisions = detail.Grid();
    int row = 0;
    for (double z = w.z0; z < w.z1 - 0.05; z += course, ++row) {
        double z1 = std::min(w.z1, z + course);
        double u = -(row % 2) * unit * 0.5;
        int col = 0;
        while (u < w.length - 0.05) {
            double len = unit * (0.75 + 0.5 * Hash01(seed, row, col));
            double u0 = std::max(0.0, u), u1 = std::min(w.length, u + len);
            u += len;
            ++col;
            if (u1 - u0 < 0.08 || StoneHitsOpening(w, u0, u1, z, z1)) continue;
            Frame f{g.P(u0, z, depth), w.along, kUp, out};
            Stone(em, f, u1 - u0, z1 - z, style,
                  seed * 1000003 + uint64_t(row) * 4099 + uint64_t(col), w.material);
        }
    }
}

}  // namespace

void EmitWall(Emitter& em, const WallSpec& w, const Detail& detail) {
    WallGeom g{w};
    int arch_segments = detail.Seg(12);
    EmitFace(em, g, 0, w.inward, arch_segments);
    EmitFace(em, g, w.thickness, -w.inward, arch_segments);
    for (const Opening& o : w.openings) {
        EmitReveals(em, g, o, arch_segments);
        if (o.moulded) {
            EmitMoulding(em, g, o.AtFace(true), 0, w.inward, detail);
            EmitMoulding(em, g, o.AtFace(false), w.thickness, -w.inward, detail);
        }
        if (o.kind == OpeningKind::kWindow)
            EmitGlazing(em, g, o, detail, w.seed * 31 + uint64_t(o.center * 100));
        if (o.kind == OpeningKind::kDoor) EmitDoor(em, g, o, detail);
    }
    double t = w.thickness;
    if (w.close_ends) {
        for (double u : {0.0, w.length}) {
            Vec3d out = u == 0 ? -w.along : w.along;
            em.Quad(g.P(u, w.z0, 0), g.P(u, w.z1, 0), g.P(u, w.z1, t), g.P(u, w.z0, t), out,
                    w.material);
        }
    }
    em.Quad(g.P(0, w.z1, 0), g.P(w.length, w.z1, 0), g.P(w.length, w.z1, t), g.P(0, w.z1, t), kUp,
            w.material);
    if (w.z0 > 0) {
        em.Quad(g.P(0, w.z0, 0), g.P(w.length, w.z0, 0), g.P(w.length, w.z0, t), g.P(0, w.z0, t),
                -kUp, w.material);
    }
    if (w.stones_inside) EmitStones(em, g, 0, w.inward, detail, w.seed * 2 + 1);
    if (w.stones_outside) EmitStones(em, g, t, -w.inward, detail, w.seed * 2 + 2);
}

}  // namespace nave::preprocess::abbey
