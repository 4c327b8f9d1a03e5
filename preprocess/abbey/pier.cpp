#include "preprocess/abbey/pier.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"

namespace nave::preprocess::abbey {
namespace {

constexpr double kPi = std::numbers::pi;

// Appends an arc of the circle (cx, cz, r) from angle a0 to a1 (radians) to a profile.
void Arc(std::vector<Vec2>& p, double cx, double cz, double r, double a0, double a1, int n) {
    for (int i = 0; i <= n; ++i) {
        double a = a0 + (a1 - a0) * i / n;
        p.push_back({cx + r * std::cos(a), cz + r * std::sin(a)});
    }
}

}  // namespace

void EmitPier(Emitter& em, const PierSpec& s, const Detail& detail) {
    const double r = s.radius;
    const int around = 8 * ((detail.Seg(32) + 7) / 8);  // a multiple of 8 for the octagonal parts
    const int arc = detail.Seg(4);
    const double plinth_h = 0.40, base_h = 0.42, abacus_h = 0.30, capital_h = 0.95;
    const double capital_z = s.top - abacus_h - capital_h;

    // Octagonal plinth (limestone).
    Revolve(em, s.base, {{0, 0}, {r + 0.35, 0}, {r + 0.35, plinth_h}, {0, plinth_h}}, around,
            kLimestone, 8, kPi / 8);

    // Base and shaft in one profile from the plinth's top up to the capital.
    std::vector<Vec2> p;
    double z = plinth_h;
    p.push_back({0, z});
    p.push_back({r + 0.20, z});
    Arc(p, r + 0.12, z + 0.09, 0.09, -kPi / 2, kPi / 2, arc);                 // lower torus
    Arc(p, r + 0.14, z + 0.26, 0.08, -kPi / 2 - 0.3, -kPi * 1.5 + 0.3, arc);  // scotia (concave)
    Arc(p, r + 0.05, z + 0.36, 0.05, -kPi / 2, kPi / 2, arc);                 // upper torus
    z += base_h;
    p.push_back({r, z});
    // Drums of 0.5 m with small V-shaped joints.
    const double drum = 0.5 * detail.UnitScale(), joint = 0.012;
    for (double zj = z + drum; zj < capital_z - 0.3; zj += drum) {
        p.push_back({r, zj - joint});
        p.push_back({r - joint, zj});
        p.push_back({r, zj + joint});
    }
    p.push_back({r, capital_z - 0.06});
    Arc(p, r, capital_z - 0.03, 0.035, -kPi / 2, kPi / 2, arc);  // astragal
    p.push_back({0, capital_z});
    Revolve(em, s.base, p, around, kLimestone);

    // Bell capital: flares from the shaft to the abacus (concave, like a chalice).
    std::vector<Vec2> bell;
    bell.push_back({0, capital_z});
    int n = detail.Seg(8);
    for (int i = 0; i <= n; ++i) {
        double t = double(i) / n;
        bell.push_back({r + 0.32 * t * t, capital_z + capital_h * t});
    }
    bell.push_back({0, capital_z + capital_h});
    Revolve(em, s.base, bell, around, kLimestoneDark);

    // Crockets: small knobs curling out under the abacus, eight round the bell.
    for (int k = 0; k < 8; ++k) {
        double a = kPi / 8 + k * kPi / 4;
        Vec3d c = s.base + Vec3d(std::cos(a) * (r + 0.26), std::sin(a) * (r + 0.26),
                                 capital_z + capital_h - 0.16);
        std::vector<Vec2> knob;
        Arc(knob, 0, 0, 0.1, -kPi / 2, kPi / 2, detail.Seg(4));
        for (auto& q : knob) q.x = std::max(0.0, q.x);
        Revolve(em, c, knob, std::max(6, around / 4), kLimestoneDark);
    }

    // Octagonal abacus with a chamfered upper edge.
    double ab = r + 0.45;
    Revolve(em, s.base + Vec3d(0, 0, capital_z + capital_h),
            {{0, 0}, {ab, 0}, {ab, abacus_h - 0.06}, {ab - 0.06, abacus_h}, {0, abacus_h}}, around,
            kLimestoneDark, 8, kPi / 8);
    (void)s.seed;
}

}  // namespace nave::preprocess::abbey
