#include "preprocess/abbey/primitives.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nave::preprocess::abbey {

double Hash01(uint64_t a, uint64_t b, uint64_t c) {
    // SplitMix64 finaliser (Steele, Lea, Flood 2014) over a combination of the inputs.
    uint64_t x = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full ^
                 (c + 0x165667B19E3779F9ull) * 0x27D4EB2F165667C5ull;
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    x ^= x >> 31;
    return double(x >> 11) * (1.0 / 9007199254740992.0);
}

double PointedArch(double t, double rho) {
    t = std::clamp(t, 0.0, 1.0);
    double d = t + rho - 1;
    double h = std::sqrt(std::max(0.0, rho * rho - d * d));
    return h / std::sqrt(2 * rho - 1);
}

void Box(Emitter& em, const Vec3d& lo, const Vec3d& hi, uint32_t m) {
    Vec3d c = (lo + hi) * 0.5, h = (hi - lo) * 0.5;
    OrientedBox(em, c, Vec3d(h.x, 0, 0), Vec3d(0, h.y, 0), Vec3d(0, 0, h.z), m);
}

void OrientedBox(Emitter& em, const Vec3d& center, const Vec3d& a, const Vec3d& b, const Vec3d& c,
                 uint32_t material) {
    const Vec3d* axes[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
        const Vec3d& n = *axes[k];
        const Vec3d& p = *axes[(k + 1) % 3];
        const Vec3d& q = *axes[(k + 2) % 3];
        for (double s : {-1.0, 1.0}) {
            Vec3d f = center + n * s;
            em.Quad(f - p - q, f + p - q, f + p + q, f - p + q, n * s, material);
        }
    }
}

void Stone(Emitter& em, const Frame& f, double lu, double lv, const StoneStyle& style,
           uint64_t seed, uint32_t material) {
    double j = style.joint, c = std::min({style.chamfer, lu * 0.25, lv * 0.25});
    double u0 = j, u1 = lu - j, v0 = j, v1 = lv - j;
    if (u1 - u0 <= 2 * c || v1 - v0 <= 2 * c) return;
    int n = std::max(1, style.subdivisions);
    // Front face grid, tooled inside (the border stays flat so the chamfers meet it exactly).
    auto front = [&](int i, int k) {
        double x = u0 + c + (u1 - u0 - 2 * c) * i / n;
        double y = v0 + c + (v1 - v0 - 2 * c) * k / n;
        double z = style.relief;
        if (i > 0 && i < n && k > 0 && k < n) z += style.tooling * (2 * Hash01(seed, i, k) - 1);
        return f.At(x, y, z);
    };
    for (int k = 0; k < n; ++k) {
        for (int i = 0; i < n; ++i) {
            em.Quad(front(i, k), front(i + 1, k), front(i + 1, k + 1), front(i, k + 1), f.w,
                    material);
        }
    }
    // Rounded arrises: from the wall face at the stone's edge up to the face border, n segments
    // along each side and m = n / 2 across (a quarter round; m = 1 is a plain chamfer).
    const int m = std::max(1, n / 2);
    const double kHalfPi = std::numbers::pi / 2;
    // Point on the arris of side (du, dv) at position `along` in [0, 1] and `across` in [0, 1].
    auto arris = [&](int side, double along, double across) {
        double inset = c * (1 - std::cos(across * kHalfPi)),
               z = style.relief * std::sin(across * kHalfPi);
        if (m == 1) inset = c * across, z = style.relief * across;
        double x0 = u0 + inset, x1 = u1 - inset, y0 = v0 + inset, y1 = v1 - inset;
        switch (side) {
            case 0:
                return f.At(x0 + (x1 - x0) * along, y0, z);  // bottom edge
            case 1:
                return f.At(x0 + (x1 - x0) * along, y1, z);  // top
            case 2:
                return f.At(x0, y0 + (y1 - y0) * along, z);  // left
            default:
                return f.At(x1, y0 + (y1 - y0) * along, z);  // right
        }
    };
    const Vec3d outs[4] = {f.w - f.v, f.w + f.v, f.w - f.u, f.w + f.u};
    for (int side = 0; side < 4; ++side) {
        for (int i = 0; i < n; ++i) {
            double a = double(i) / n, b = double(i + 1) / n;
            for (int k = 0; k < m; ++k) {
                double p = double(k) / m, q = double(k + 1) / m;
                // The last row meets the tooled face's border vertices exactly (same formula at
                // across = 1).
                em.Quad(arris(side, a, p), arris(side, b, p), arris(side, b, q), arris(side, a, q),
                        outs[side], material);
            }
        }
    }
}

namespace {

/// A profile edge's normal at its two ends, in the profile's plane.
struct EdgeEndNormals {
    Vec2 start, end;
};

/// Smooths a profile's normals: `edge_normal[k]` is the unit normal of edge k (points k to k + 1),
/// zero for an edge of no length. Where two consecutive edges turn by less than 30 degrees the
/// profile samples a curve (a torus, a bell, a circle) and both ends take the edges' mean, so the
/// surface shades smooth; a sharper turn is a corner drawn on purpose (a plinth, a joint, a
/// chamfer) and each edge keeps its own normal there: a crease. (30 degrees is the usual
/// auto-smooth angle of modelling tools.)
std::vector<EdgeEndNormals> SmoothProfileNormals(const std::vector<Vec2>& edge_normal,
                                                 bool closed) {
    const double kSmoothTurnCos = 0.8660254037844387;  // cos 30 degrees
    const size_t n = edge_normal.size();
    std::vector<EdgeEndNormals> out(n);
    for (size_t k = 0; k < n; ++k) out[k] = {edge_normal[k], edge_normal[k]};
    auto valid = [&](size_t k) { return edge_normal[k].x != 0 || edge_normal[k].y != 0; };
    for (size_t k = 0; k < n; ++k) {
        if (!valid(k)) continue;
        // The next edge of some length after k (wrapping round a closed profile).
        size_t next = k;
        for (size_t step = 1; step < n; ++step) {
            const size_t j = k + step;
            if (j >= n && !closed) break;
            if (valid(j % n)) {
                next = j % n;
                break;
            }
        }
        if (next == k) continue;
        const Vec2 &a = edge_normal[k], &b = edge_normal[next];
        if (a.x * b.x + a.y * b.y < kSmoothTurnCos) continue;
        Vec2 mean{a.x + b.x, a.y + b.y};
        const double len = std::hypot(mean.x, mean.y);
        mean = {mean.x / len, mean.y / len};
        out[k].end = mean;
        out[next].start = mean;
    }
    return out;
}

}  // namespace

void Revolve(Emitter& em, const Vec3d& base, const std::vector<Vec2>& profile, int segments,
             uint32_t m, int sides, double phase) {
    const double kTwoPi = 2 * std::numbers::pi;
    auto dir = [&](int i) {
        double a = phase + kTwoPi * i / segments;
        if (sides > 0) {
            // A regular polygon: the radius is scaled so that the apothem equals the profile
            // radius.
            double sector = kTwoPi / sides;
            double local = std::fmod(a - phase, sector) - sector / 2;
            double scale = std::cos(sector / 2) / std::cos(local) / std::cos(sector / 2);
            return Vec3d(std::cos(a) * scale, std::sin(a) * scale, 0);
        }
        return Vec3d(std::cos(a), std::sin(a), 0);
    };
    // Each edge's right-hand normal (r, z): outward for an upward profile.
    std::vector<Vec2> edge_normal(profile.size() > 1 ? profile.size() - 1 : 0);
    for (size_t k = 0; k < edge_normal.size(); ++k) {
        const double dr = profile[k + 1].x - profile[k].x, dz = profile[k + 1].y - profile[k].y;
        const double len = std::hypot(dr, dz);
        if (len > 0) edge_normal[k] = {dz / len, -dr / len};
    }
    const std::vector<EdgeEndNormals> normals = SmoothProfileNormals(edge_normal, false);
    for (size_t k = 0; k < edge_normal.size(); ++k) {
        if (edge_normal[k].x == 0 && edge_normal[k].y == 0) continue;
        const Vec2 p0 = profile[k], p1 = profile[k + 1];
        const Vec2 m0 = normals[k].start, m1 = normals[k].end;
        for (int i = 0; i < segments; ++i) {
            Vec3d d0 = dir(i), d1 = dir(i + 1);
            Vec3d a = base + d0 * p0.x + Vec3d(0, 0, p0.y),
                  b = base + d1 * p0.x + Vec3d(0, 0, p0.y);
            Vec3d c = base + d1 * p1.x + Vec3d(0, 0, p1.y),
                  d = base + d0 * p1.x + Vec3d(0, 0, p1.y);
            const Vec3d r0 = Normalize(Vec3d(d0.x, d0.y, 0)), r1 = Normalize(Vec3d(d1.x, d1.y, 0));
            const Vec3d na = r0 * m0.x + Vec3d(0, 0, m0.y), nb = r1 * m0.x + Vec3d(0, 0, m0.y);
            const Vec3d nc = r1 * m1.x + Vec3d(0, 0, m1.y), nd = r0 * m1.x + Vec3d(0, 0, m1.y);
            const Vec3d out =
                r0 * (edge_normal[k].x) + r1 * edge_normal[k].x + Vec3d(0, 0, 2 * edge_normal[k].y);
            if (sides > 0) {
                em.Quad(a, b, c, d, out, m);
            } else {
                em.QuadN(a, b, c, d, na, nb, nc, nd, out, m);
            }
        }
    }
}

void Sweep(Emitter& em, const std::vector<Vec3d>& raw_path, const Vec3d& side,
           const std::vector<Vec2>& profile, uint32_t m, bool caps) {
    // Repeated points (an arch whose springing is also the jamb's top) have no tangent: drop them.
    std::vector<Vec3d> path;
    for (const Vec3d& p : raw_path) {
        if (path.empty() || Length(p - path.back()) > 1e-9) path.push_back(p);
    }
    size_t np = path.size(), nq = profile.size();
    if (np < 2 || nq < 3) return;
    std::vector<Vec3d> ring_prev(nq), ring(nq);
    auto make_ring = [&](size_t i, std::vector<Vec3d>& out) {
        Vec3d t = path[std::min(i + 1, np - 1)] - path[i > 0 ? i - 1 : 0];
        Vec3d n = Normalize(Cross(side, t));
        for (size_t q = 0; q < nq; ++q) out[q] = path[i] + side * profile[q].x + n * profile[q].y;
    };
    // The profile's normals in its (b, n) plane: (dy, -dx) is outward on a counter-clockwise
    // profile; smooth where it samples a curve, creased at its corners.
    std::vector<Vec2> edge_normal(nq);
    for (size_t q = 0; q < nq; ++q) {
        const Vec2 &a = profile[q], &b = profile[(q + 1) % nq];
        const double len = std::hypot(b.x - a.x, b.y - a.y);
        if (len > 0) edge_normal[q] = {(b.y - a.y) / len, -(b.x - a.x) / len};
    }
    const std::vector<EdgeEndNormals> normals = SmoothProfileNormals(edge_normal, true);
    // The ring's in-plane normal axis at path point i.
    auto ring_axis = [&](size_t i) {
        Vec3d t = path[std::min(i + 1, np - 1)] - path[i > 0 ? i - 1 : 0];
        return Normalize(Cross(side, t));
    };
    make_ring(0, ring_prev);
    Vec3d axis_prev = ring_axis(0);
    for (size_t i = 1; i < np; ++i) {
        make_ring(i, ring);
        const Vec3d axis = ring_axis(i);
        for (size_t q = 0; q < nq; ++q) {
            if (edge_normal[q].x == 0 && edge_normal[q].y == 0) continue;
            size_t r = (q + 1) % nq;
            auto normal = [&](const Vec2& v, const Vec3d& n_axis) {
                return side * v.x + n_axis * v.y;
            };
            const Vec3d n0 = normal(normals[q].start, axis_prev),
                        n1 = normal(normals[q].end, axis_prev);
            const Vec3d n2 = normal(normals[q].end, axis), n3 = normal(normals[q].start, axis);
            const Vec3d out = normal(edge_normal[q], axis_prev) + normal(edge_normal[q], axis);
            em.QuadN(ring_prev[q], ring_prev[r], ring[r], ring[q], n0, n1, n2, n3, out, m);
        }
        std::swap(ring_prev, ring);
        axis_prev = axis;
    }
    if (caps) {
        std::vector<Vec3d> first(nq), last(nq);
        make_ring(0, first);
        make_ring(np - 1, last);
        Vec3d t0 = path[0] - path[1], t1 = path[np - 1] - path[np - 2];
        for (size_t q = 1; q + 1 < nq; ++q) {
            em.Tri(first[0], first[q], first[q + 1], t0, m);
            em.Tri(last[0], last[q], last[q + 1], t1, m);
        }
    }
}

void ParamGrid(Emitter& em, const std::function<Vec3d(double, double)>& p, int ns, int nt,
               const std::function<Vec3d(const Vec3d&)>& outward, uint32_t m) {
    std::vector<Vec3d> pts((ns + 1) * (nt + 1)), nrm((ns + 1) * (nt + 1));
    const double e = 1e-4;
    for (int j = 0; j <= nt; ++j) {
        for (int i = 0; i <= ns; ++i) {
            double s = double(i) / ns, t = double(j) / nt;
            pts[j * (ns + 1) + i] = p(s, t);
            double s0 = std::max(0.0, s - e), s1 = std::min(1.0, s + e);
            double t0 = std::max(0.0, t - e), t1 = std::min(1.0, t + e);
            Vec3d n = Cross(p(s1, t) - p(s0, t), p(s, t1) - p(s, t0));
            Vec3d o = outward(pts[j * (ns + 1) + i]);
            double len = Length(n);
            if (len > 0 && Dot(n, o) < 0) n = -n;
            nrm[j * (ns + 1) + i] = len > 0 ? n / len : Normalize(o);
        }
    }
    for (int j = 0; j < nt; ++j) {
        for (int i = 0; i < ns; ++i) {
            int a = j * (ns + 1) + i, b = a + 1, c = a + ns + 2, d = a + ns + 1;
            Vec3d out = outward((pts[a] + pts[c]) * 0.5);
            em.QuadN(pts[a], pts[b], pts[c], pts[d], nrm[a], nrm[b], nrm[c], nrm[d], out, m);
        }
    }
}

std::vector<Vec2> CircleProfile(double radius, int n, double center_n) {
    std::vector<Vec2> out;
    for (int i = 0; i < n; ++i) {
        double a = 2 * std::numbers::pi * i / n;
        out.push_back({radius * std::cos(a), center_n + radius * std::sin(a)});
    }
    return out;
}

}  // namespace nave::preprocess::abbey
