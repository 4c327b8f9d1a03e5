#include "preprocess/abbey/abbey_plan.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/pier.h"
#include "preprocess/abbey/primitives.h"
#include "preprocess/abbey/surfaces.h"
#include "preprocess/abbey/vault.h"
#include "preprocess/abbey/wall.h"

namespace nave::preprocess::abbey {
namespace {

constexpr double kPi = std::numbers::pi;

// Plan and elevation, in metres (docs/abbey.md). x east, y north, z up; the west facade's inner
// face is at x = 0, the church's axis is y = 0.
constexpr double kBay = 7.0;  // nave bay (pier spacing)
constexpr int kNaveBays = 8;  // x 0..56
constexpr double kCrossingX0 = 56, kCrossingX1 = 69;
constexpr double kChoirX1 = 83;                            // hemicycle centre
constexpr double kArcadeY = 6.5;                           // pier axes
constexpr double kUpperWallT = 1.2;                        // upper (clerestory) wall thickness
constexpr double kNaveInner = kArcadeY - kUpperWallT / 2;  // 5.9: inner face of the upper walls
constexpr double kAisleWall = 13.0;                        // inner face of the aisle walls
constexpr double kOuterWallT = 1.2;
constexpr double kTransept = 27.0;                       // inner face of the transept end walls
constexpr double kArcadeSpring = 8.75;                   // top of the pier abaci
constexpr double kVaultSpring = 20.0, kVaultRise = 8.0;  // nave vault crown at 28 m
constexpr double kAisleRise = 5.25;                      // aisle vault crown at 14 m
constexpr double kWallTop = 30.0, kAisleWallTop = 15.5;
constexpr double kRidge = 39.0;
constexpr double kAmbulatory = 13.0;  // inner face of the ambulatory wall (radius)
constexpr double kChapelRadius = 3.0;
// The hemicycle: five bays of 36 degrees round the apse centre, so that one radiating chapel is on
// the axis.
constexpr int kApseBays = 5;
constexpr double kApseStep = 180.0 / kApseBays;
const Vec3d kApse(kChoirX1, 0, 0);

Vec3d Dir(double degrees) {
    double a = degrees * kPi / 180;
    return Vec3d(std::cos(a), std::sin(a), 0);
}

// The ambulatory's radiating chapels sit on the bisectors of the hemicycle's six bays.
double ChapelAngle(int k) { return -90.0 + kApseStep * (k + 0.5); }
// Angle of the k-th radial line of the hemicycle (k = 0 south, kApseBays north).
double ApseAngle(int k) { return -90.0 + kApseStep * k; }
Vec3d ChapelCentre(int k) {
    return kApse +
           Dir(ChapelAngle(k)) * (kAmbulatory * std::cos(kApseStep / 2 * kPi / 180) + kOuterWallT);
}

// A triangular prism: the triangle a b c extruded by `e` (gables).
void Prism(Emitter& em, const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& e,
           uint32_t m) {
    Vec3d n = Cross(b - a, c - a);
    em.Tri(a, b, c, Dot(n, e) > 0 ? -n : n, m);
    em.Tri(a + e, b + e, c + e, Dot(n, e) > 0 ? n : -n, m);
    Vec3d centre = (a + b + c) * (1.0 / 3) + e * 0.5;
    const Vec3d* v[3] = {&a, &b, &c};
    for (int i = 0; i < 3; ++i) {
        const Vec3d& p = *v[i];
        const Vec3d& q = *v[(i + 1) % 3];
        em.Quad(p, q, q + e, p + e, (p + q) * 0.5 + e * 0.5 - centre, m);
    }
}

WallSpec Wall(Vec3d origin, Vec3d along, Vec3d inward, double length, double z0, double z1,
              double thickness, uint64_t seed) {
    WallSpec w;
    w.origin = origin;
    w.along = along;
    w.inward = inward;
    w.length = length;
    w.z0 = z0;
    w.z1 = z1;
    w.thickness = thickness;
    w.material = kLimestone;
    w.seed = seed;
    return w;
}

// A side of a convex polygonal wall (hemicycle, ambulatory, chapels) from a to b, interior to the
// left. Each side is lengthened by thickness * tan(turn / 2) at both ends so that neighbouring
// sides close the wedge between them on the outside (the overlap is hidden inside the neighbour).
WallSpec PolygonSide(Vec3d a, Vec3d b, double turn_degrees, double z0, double z1, double thickness,
                     uint64_t seed) {
    Vec3d along = Normalize(b - a);
    double e = thickness * std::tan(turn_degrees / 2 * kPi / 180);
    WallSpec w = Wall(a - along * e, along, Cross(Vec3d(0, 0, 1), along), Length(b - a) + 2 * e, z0,
                      z1, thickness, seed);
    return w;
}

// Windows splay 0.6 m to each face of the wall from the glass in its middle: through a 1.2 m wall
// with straight reveals a 2.6 m lancet would take no sun more than 65 degrees off its normal (the
// summer morning sun at Royaumont stands 69 degrees off the south walls' normal).
constexpr double kSplay = 0.6;

// The inner sill slopes down 1.8 m from the glass (a glacis): light falling at 48 degrees drops
// that much across the inner half of the wall.
constexpr double kGlacis = 1.8;

Opening Window(double center, double half_width, double sill, double spring, double rise,
               double splay = kSplay, double glacis = kGlacis) {
    Opening o;
    o.splay = splay;
    o.glacis = glacis;
    o.center = center;
    o.half_width = half_width;
    o.sill = sill;
    o.spring = spring;
    o.rise = rise;
    o.kind = OpeningKind::kWindow;
    return o;
}

Opening Arch(double center, double half_width, double sill, double spring, double rise) {
    Opening o = Window(center, half_width, sill, spring, rise, 0, 0);
    o.kind = OpeningKind::kOpen;
    return o;
}

}  // namespace

bool InsidePlan(double x, double y) {
    double ay = std::abs(y);
    if (x >= 0 && x <= kCrossingX0 && ay <= kAisleWall) return true;
    if (x >= kCrossingX0 && x <= kCrossingX1 && ay <= kTransept) return true;
    if (x >= kCrossingX1 && x <= kChoirX1 && ay <= kAisleWall) return true;
    if (x >= kChoirX1) {
        Vec3d d(x - kApse.x, y, 0);
        double r = Length(d);
        // The ambulatory is a polygon whose inner faces are at distance 13 cos(step / 2) at the
        // bisectors; a disc of that radius is inside it.
        if (r <= kAmbulatory * std::cos(kApseStep / 2 * kPi / 180)) return true;
        for (int k = 0; k < kApseBays; ++k) {
            Vec3d q = ChapelCentre(k);
            Vec3d dq(x - q.x, y - q.y, 0);
            Vec3d axis = Dir(ChapelAngle(k));
            if (Length(dq) <= kChapelRadius) return true;
            // Between the chapel and the ambulatory: the opening through the wall.
            double along = Dot(dq, axis);
            double across = std::abs(Dot(dq, Cross(Vec3d(0, 0, 1), axis)));
            if (along <= 0 && along >= -kOuterWallT - 0.05 && across <= 2.6) return true;
        }
        // Ambulatory sectors: inside the polygon through the six bay corners at radius 13.
        double a = std::atan2(y, x - kApse.x) * 180 / kPi;
        if (a < -90 || a > 90) return false;
        int k = std::min(kApseBays - 1, int((a + 90) / kApseStep));
        Vec3d p0 = kApse + Dir(ApseAngle(k)) * kAmbulatory,
              p1 = kApse + Dir(ApseAngle(k + 1)) * kAmbulatory;
        Vec3d e = p1 - p0, v(x - p0.x, y - p0.y, 0);
        return Cross(e, v).z >= 0;  // left of the edge going counter-clockwise = inside
    }
    return false;
}

std::vector<AbbeyPart> AbbeyParts(const Detail& detail) {
    std::vector<AbbeyPart> parts;
    auto add = [&](std::string name, std::function<void(Emitter&)> f) {
        parts.push_back({std::move(name), std::move(f)});
    };
    const Detail d = detail;
    uint64_t seed = 1;

    // Floor: tiles over the plan, in strips of 4 m so that no part is huge.
    for (double x = -0.5; x < 100; x += 4) {
        add(fmt::format("floor x={}", x), [=](Emitter& em) {
            EmitTiledFloor(em, x, x + 4, -kTransept, kTransept, InsidePlan, d);
        });
    }

    // Piers: nave (x = 7..49), crossing, choir, hemicycle.
    std::vector<Vec3d> piers;
    for (int i = 1; i < kNaveBays; ++i) {
        for (double s : {-1.0, 1.0}) piers.push_back(Vec3d(i * kBay, s * kArcadeY, 0));
    }
    for (double x : {kCrossingX0, kCrossingX1, kCrossingX1 + kBay}) {
        for (double s : {-1.0, 1.0}) piers.push_back(Vec3d(x, s * kArcadeY, 0));
    }
    for (int k = 0; k <= kApseBays; ++k) piers.push_back(kApse + Dir(ApseAngle(k)) * kArcadeY);
    for (size_t i = 0; i < piers.size(); ++i) {
        PierSpec p;
        p.base = piers[i];
        bool crossing =
            std::abs(piers[i].x - kCrossingX0) < 0.1 || std::abs(piers[i].x - kCrossingX1) < 0.1;
        p.radius = crossing ? 1.0 : 0.8;
        p.top = kArcadeSpring;
        p.seed = i;
        add(fmt::format("pier {}", i), [=](Emitter& em) { EmitPier(em, p, d); });
    }

    // Upper walls of nave and choir: arcade arches below, clerestory windows above. A wall course
    // holds one opening per column, so the arcade storey and the clerestory storey are two courses
    // (split at 17 m).
    const double kStorey = 17.0;
    auto upper_wall = [&](double x0, int bays, double side, const std::string& name) {
        Vec3d origin(x0, side * kNaveInner, 0);
        WallSpec arcade = Wall(origin, Vec3d(1, 0, 0), Vec3d(0, -side, 0), bays * kBay,
                               kArcadeSpring, kStorey, kUpperWallT, seed++);
        WallSpec clerestory = Wall(origin, Vec3d(1, 0, 0), Vec3d(0, -side, 0), bays * kBay, kStorey,
                                   kWallTop, kUpperWallT, seed++);
        for (int b = 0; b < bays; ++b) {
            double c = (b + 0.5) * kBay;
            arcade.openings.push_back(Arch(c, kBay / 2 - 0.9, kArcadeSpring, kArcadeSpring, 4.9));
            clerestory.openings.push_back(Window(c, 1.3, kVaultSpring, 23.6, 2.2));
        }
        add(name, [=](Emitter& em) {
            EmitWall(em, arcade, d);
            EmitWall(em, clerestory, d);
        });
    };
    for (double s : {-1.0, 1.0}) {
        upper_wall(0, kNaveBays, s, "nave upper wall");
        upper_wall(kCrossingX1, 2, s, "choir upper wall");
    }
    // Hemicycle upper walls: narrow bays between the apse piers.
    for (int k = 0; k < kApseBays; ++k) {
        Vec3d a = kApse + Dir(ApseAngle(k)) * kNaveInner,
              b = kApse + Dir(ApseAngle(k + 1)) * kNaveInner;
        // Counter-clockwise round the apse: the interior is on the left. Two storeys, as in the
        // nave.
        WallSpec w = PolygonSide(a, b, kApseStep, kArcadeSpring, kStorey, kUpperWallT, seed++);
        WallSpec up = PolygonSide(a, b, kApseStep, kStorey, kWallTop, kUpperWallT, seed++);
        double c = w.length / 2;
        w.openings.push_back(Arch(c, 0.95, kArcadeSpring, kArcadeSpring + 1.5, 3.6));
        up.openings.push_back(Window(c, 0.55, kVaultSpring, 23.8, 1.2, 0.35));
        add(fmt::format("hemicycle wall {}", k), [=](Emitter& em) {
            EmitWall(em, w, d);
            EmitWall(em, up, d);
        });
    }

    // Aisle walls with a window per bay, and the buttresses and flying buttresses between the bays.
    for (double s : {-1.0, 1.0}) {
        auto aisle_wall = [&](double x0, double x1, const std::string& name) {
            WallSpec w = Wall(Vec3d(x0, s * kAisleWall, 0), Vec3d(1, 0, 0), Vec3d(0, -s, 0),
                              x1 - x0, 0, kAisleWallTop, kOuterWallT, seed++);
            for (double c = kBay / 2; c < x1 - x0; c += kBay) {
                w.openings.push_back(Window(c, 1.0, 3.5, 9.0, 2.0));
            }
            add(name, [=](Emitter& em) { EmitWall(em, w, d); });
        };
        aisle_wall(0, kCrossingX0 - kOuterWallT, "nave aisle wall");
        aisle_wall(kCrossingX1 + kOuterWallT, kChoirX1, "choir aisle wall");
        for (double x = kBay; x < kChoirX1 + 0.1; x += kBay) {
            if (x > kCrossingX0 - 1 && x < kCrossingX1 + 1) continue;
            double y0 = s * (kAisleWall + kOuterWallT);
            WallSpec b = Wall(Vec3d(x - 0.6, y0, 0), Vec3d(0, s, 0), Vec3d(-1, 0, 0), 2.0, 0, 14.5,
                              1.2, seed++);
            add("buttress", [=](Emitter& em) {
                EmitWall(em, b, d);
                // Pinnacle and flyer to the clerestory wall.
                Revolve(em, Vec3d(x, y0 + s * 1.0, 14.5), {{0, 0}, {0.55, 0}, {0, 3.0}},
                        4 * d.Seg(1), kLimestone, 4, kPi / 4);
                std::vector<Vec3d> path;
                Vec3d a(x, y0 + s * 0.2, 14.2), e(x, s * (kArcadeY + kUpperWallT / 2), 23.0);
                int n = d.Seg(16);
                for (int i = 0; i <= n; ++i) {
                    double t = double(i) / n;
                    path.push_back(a + (e - a) * t + Vec3d(0, 0, 1.4 * std::sin(kPi * t)));
                }
                Sweep(em, path, Vec3d(1, 0, 0),
                      {{-0.3, -0.4}, {0.3, -0.4}, {0.3, 0.4}, {-0.3, 0.4}}, kLimestone);
            });
        }
    }

    // West facade: portal with doors, a great west window, aisle windows; gable above.
    {
        double width = 2 * (kAisleWall + kOuterWallT);
        WallSpec w = Wall(Vec3d(0, kAisleWall + kOuterWallT, 0), Vec3d(0, -1, 0), Vec3d(1, 0, 0),
                          width, 0, kWallTop, 1.5, seed++);
        double mid = width / 2;
        w.openings.push_back(Window(mid - 9.75, 1.0, 3.5, 9.0, 2.0));
        Opening portal = Arch(mid, 1.8, 0, 4.5, 2.4);
        portal.kind = OpeningKind::kDoor;
        w.openings.push_back(portal);
        w.openings.push_back(Window(mid + 9.75, 1.0, 3.5, 9.0, 2.0));
        // The west window sits above the portal: a second wall course keeps openings one per
        // column.
        WallSpec upper = w;
        w.z1 = 12.0;
        upper.z0 = 12.0;
        upper.openings = {Window(mid, 2.4, 13.0, 21.5, 3.6, kSplay, 0.7)};
        upper.seed = seed++;
        add("west facade", [=](Emitter& em) {
            EmitWall(em, w, d);
            EmitWall(em, upper, d);
            Prism(em, Vec3d(0, -(kArcadeY + 1.2), kWallTop), Vec3d(0, kArcadeY + 1.2, kWallTop),
                  Vec3d(0, 0, kRidge), Vec3d(-1.5, 0, 0), kLimestone);
        });
    }

    // Transept: west and east walls of each arm, end walls with two tall lancets, gables.
    for (double s : {-1.0, 1.0}) {
        for (int east = 0; east < 2; ++east) {
            double x = east ? kCrossingX1 : kCrossingX0;
            Vec3d inward(east ? -1 : 1, 0, 0);
            // Over the aisle (|y| 6.5..13): wall above the aisle vault only.
            WallSpec over = Wall(Vec3d(x, s * kArcadeY, 0), Vec3d(0, s, 0), inward,
                                 kAisleWall - kArcadeY, 13.0, kWallTop, kOuterWallT, seed++);
            WallSpec arm = Wall(Vec3d(x, s * kAisleWall, 0), Vec3d(0, s, 0), inward,
                                kTransept - kAisleWall, 0, kWallTop, kOuterWallT, seed++);
            arm.openings = {Window(3.5, 1.0, 3.5, 9.0, 2.0), Window(10.5, 1.0, 3.5, 9.0, 2.0)};
            WallSpec clerestory = arm;
            arm.z1 = 17.0;
            clerestory.z0 = 17.0;
            clerestory.openings = {Window(3.5, 1.2, 19.0, 23.5, 2.2),
                                   Window(10.5, 1.2, 19.0, 23.5, 2.2)};
            clerestory.seed = seed++;
            add("transept side wall", [=](Emitter& em) {
                EmitWall(em, over, d);
                EmitWall(em, arm, d);
                EmitWall(em, clerestory, d);
            });
        }
        double x0 = kCrossingX0 - kOuterWallT, x1 = kCrossingX1 + kOuterWallT;
        Vec3d origin = s > 0 ? Vec3d(x0, kTransept, 0) : Vec3d(x1, -kTransept, 0);
        WallSpec end = Wall(origin, Vec3d(s, 0, 0), Vec3d(0, -s, 0), x1 - x0, 0, kWallTop,
                            kOuterWallT, seed++);
        double l = x1 - x0;
        end.openings = {Window(l / 2 - 3.0, 1.4, 6.0, 18.0, 3.0),
                        Window(l / 2 + 3.0, 1.4, 6.0, 18.0, 3.0)};
        add("transept end wall", [=](Emitter& em) {
            EmitWall(em, end, d);
            double y = s * (kTransept + kOuterWallT);
            Prism(em, Vec3d(x0 - 0.5, y, kWallTop), Vec3d(x1 + 0.5, y, kWallTop),
                  Vec3d(0.5 * (x0 + x1), y, kRidge), Vec3d(0, -s * kOuterWallT, 0), kLimestone);
        });
    }

    // Ambulatory wall, with an arch into each radiating chapel.
    for (int k = 0; k < kApseBays; ++k) {
        Vec3d a = kApse + Dir(ApseAngle(k)) * kAmbulatory,
              b = kApse + Dir(ApseAngle(k + 1)) * kAmbulatory;
        WallSpec w = PolygonSide(a, b, kApseStep, 0, kAisleWallTop, kOuterWallT, seed++);
        w.openings = {Arch(w.length / 2, 2.6, 0, 5.5, 3.0)};
        Vec3d q = ChapelCentre(k);
        Vec3d axis = Dir(ChapelAngle(k));
        std::vector<WallSpec> chapel;
        const int kSides = 5;
        for (int j = 0; j < kSides; ++j) {
            double a0 = ChapelAngle(k) - 90 + 180.0 * j / kSides,
                   a1 = ChapelAngle(k) - 90 + 180.0 * (j + 1) / kSides;
            Vec3d p0 = q + Dir(a0) * kChapelRadius, p1 = q + Dir(a1) * kChapelRadius;
            WallSpec c = PolygonSide(p0, p1, 180.0 / kSides, 0, 11.0, 0.9, seed++);
            c.openings = {Window(c.length / 2, 0.35, 3.0, 6.2, 1.0, 0.25)};
            chapel.push_back(c);
        }
        add(fmt::format("ambulatory bay {}", k), [=](Emitter& em) {
            EmitWall(em, w, d);
            for (const WallSpec& c : chapel) EmitWall(em, c, d);
            EmitHalfDome(em, q, axis, kChapelRadius, 6.8, 3.0, 3, d);
            auto cone = [=](double s, double t) {
                return q + Dir(ChapelAngle(k) - 90 + 180 * s) * ((kChapelRadius + 1.3) * (1 - t)) +
                       Vec3d(0, 0, 11.0 + 3.5 * t);
            };
            EmitSlateRoof(
                em, cone, kPi * (kChapelRadius + 1.3), 3.8,
                [=](const Vec3d& p) { return p - Vec3d(q.x, q.y, 8.0); }, d, 900 + k);
        });
    }

    // Vaults: nave, crossing, choir, transept arms, aisles, ambulatory, apse.
    auto bay = [&](Vec3d c0, Vec3d c1, Vec3d c2, Vec3d c3, double spring, double rise, bool u_max,
                   const std::string& name) {
        VaultBay v;
        v.corners = {c0, c1, c2, c3};
        v.spring = spring;
        v.rise = rise;
        v.rib_u_max = u_max;
        v.seed = seed++;
        add(name, [=](Emitter& em) { EmitVaultBay(em, v, d); });
    };
    for (int i = 0; i < kNaveBays; ++i) {
        double x0 = i * kBay, x1 = x0 + kBay;
        bay(Vec3d(x0, -kNaveInner, 0), Vec3d(x1, -kNaveInner, 0), Vec3d(x1, kNaveInner, 0),
            Vec3d(x0, kNaveInner, 0), kVaultSpring, kVaultRise, false, "nave vault");
    }
    bay(Vec3d(kCrossingX0, -kArcadeY, 0), Vec3d(kCrossingX1, -kArcadeY, 0),
        Vec3d(kCrossingX1, kArcadeY, 0), Vec3d(kCrossingX0, kArcadeY, 0), kVaultSpring, kVaultRise,
        true, "crossing vault");
    for (int i = 0; i < 2; ++i) {
        double x0 = kCrossingX1 + i * kBay, x1 = x0 + kBay;
        bay(Vec3d(x0, -kNaveInner, 0), Vec3d(x1, -kNaveInner, 0), Vec3d(x1, kNaveInner, 0),
            Vec3d(x0, kNaveInner, 0), kVaultSpring, kVaultRise, i == 1, "choir vault");
    }
    for (double s : {-1.0, 1.0}) {
        // Three bays per arm: one over the aisle's width, then two of 7 m centred on the arm's
        // clerestory windows (|y| = 16.5, 23.5), whose lateral cells then rise round them as the
        // nave's do; two equal bays put a transverse arch right over a window.
        for (auto [y0, y1] : {std::pair{kArcadeY, kAisleWall}, std::pair{kAisleWall, 20.0},
                              std::pair{20.0, kTransept}}) {
            bay(Vec3d(kCrossingX1, s * y0, 0), Vec3d(kCrossingX1, s * y1, 0),
                Vec3d(kCrossingX0, s * y1, 0), Vec3d(kCrossingX0, s * y0, 0), kVaultSpring,
                kVaultRise, false, "transept vault");
        }
        double yi = s * (kArcadeY + kUpperWallT / 2), yo = s * kAisleWall;
        for (int i = 0; i < kNaveBays; ++i) {
            double x0 = i * kBay, x1 = x0 + kBay;
            bay(Vec3d(x0, yi, 0), Vec3d(x1, yi, 0), Vec3d(x1, yo, 0), Vec3d(x0, yo, 0),
                kArcadeSpring, kAisleRise, i == kNaveBays - 1, "aisle vault");
        }
        for (int i = 0; i < 2; ++i) {
            double x0 = kCrossingX1 + i * kBay, x1 = x0 + kBay;
            bay(Vec3d(x0, yi, 0), Vec3d(x1, yi, 0), Vec3d(x1, yo, 0), Vec3d(x0, yo, 0),
                kArcadeSpring, kAisleRise, false, "choir aisle vault");
        }
    }
    for (int k = 0; k < kApseBays; ++k) {
        Vec3d d0 = Dir(ApseAngle(k)), d1 = Dir(ApseAngle(k + 1));
        double ri = kArcadeY + kUpperWallT / 2;
        bay(kApse + d0 * ri, kApse + d1 * ri, kApse + d1 * kAmbulatory, kApse + d0 * kAmbulatory,
            kArcadeSpring, kAisleRise, k == kApseBays - 1, "ambulatory vault");
    }
    add("apse vault", [=](Emitter& em) {
        // The hemicycle's windows (0.55 m half width, apex at 25 m; 0.9 m and 25.8 m on the
        // splayed inner face) stand above the dome's springing line: a lunette round each.
        Lunette lunette;
        lunette.half_width = 1.3;
        lunette.crown = 27.2;
        EmitHalfDome(em, kApse, Vec3d(1, 0, 0), kNaveInner, kVaultSpring, kVaultRise, kApseBays - 1,
                     d, lunette);
    });

    // Roofs: the main roof over nave and choir, the transept roof, the apse's half cone, lean-to
    // roofs over the aisles and the ambulatory.
    const double eave = kArcadeY + kUpperWallT / 2 + 0.6, pitch = kRidge - kWallTop;
    const double slope = std::hypot(eave, pitch);
    for (double s : {-1.0, 1.0}) {
        add("main roof", [=](Emitter& em) {
            auto r = [=](double u, double t) {
                return Vec3d(-1.5 + u * (kChoirX1 + 1.5), s * eave * (1 - t), kWallTop + pitch * t);
            };
            EmitSlateRoof(
                em, r, kChoirX1 + 1.5, slope,
                [=](const Vec3d& p) { return Vec3d(0, s * pitch, eave); }, d, 10 + (s > 0));
        });
        add("transept roof", [=](Emitter& em) {
            double xc = 0.5 * (kCrossingX0 + kCrossingX1),
                   half = 0.5 * (kCrossingX1 - kCrossingX0) + kOuterWallT + 0.6;
            double y1 = kTransept + kOuterWallT + 0.3;
            auto r = [=](double u, double t) {
                return Vec3d(xc + s * half * (1 - t), -y1 + 2 * y1 * u, kWallTop + pitch * t);
            };
            double sl = std::hypot(half, pitch);
            EmitSlateRoof(
                em, r, 2 * y1, sl, [=](const Vec3d&) { return Vec3d(s * pitch, 0, half); }, d,
                20 + (s > 0));
        });
        add("aisle roof", [=](Emitter& em) {
            double y_low = kAisleWall + kOuterWallT + 0.4, y_high = kArcadeY + kUpperWallT / 2;
            double z_low = kAisleWallTop, z_high = 19.5;
            for (std::pair<double, double> span :
                 {std::pair{-1.5, kCrossingX0 - kOuterWallT},
                  std::pair{kCrossingX1 + kOuterWallT, kChoirX1}}) {
                // Plain variables: clang before 16 cannot capture structured bindings.
                const double x0 = span.first, x1 = span.second;
                auto r = [=](double u, double t) {
                    return Vec3d(x0 + (x1 - x0) * u, s * (y_low + (y_high - y_low) * t),
                                 z_low + (z_high - z_low) * t);
                };
                EmitSlateRoof(
                    em, r, x1 - x0, std::hypot(y_low - y_high, z_high - z_low),
                    [=](const Vec3d&) { return Vec3d(0, s * (z_high - z_low), y_low - y_high); }, d,
                    30 + (s > 0) + uint64_t(int64_t(x0)));  // x0 < 0 on one side: via int64
            }
        });
    }
    add("ridges", [=](Emitter& em) {
        // Half-round ridge tiles over the main and transept ridges.
        auto ridge = [&](Vec3d a, Vec3d b, Vec3d side) {
            std::vector<Vec2> profile;
            int n = d.Seg(8);
            for (int i = 0; i <= n; ++i) {
                double t = kPi * i / n;
                profile.push_back({0.2 * std::cos(t), 0.2 * std::sin(t)});
            }
            std::vector<Vec3d> path;
            int m = std::max(2, d.Seg(40));
            for (int i = 0; i <= m; ++i) path.push_back(a + (b - a) * (double(i) / m));
            Sweep(em, path, side, profile, kRoofSlate);
        };
        ridge(Vec3d(-1.5, 0, kRidge - 0.05), Vec3d(kChoirX1, 0, kRidge - 0.05), Vec3d(0, 1, 0));
        double y1 = kTransept + kOuterWallT + 0.3, xc = 0.5 * (kCrossingX0 + kCrossingX1);
        ridge(Vec3d(xc, -y1, kRidge - 0.05), Vec3d(xc, y1, kRidge - 0.05), Vec3d(1, 0, 0));
    });
    add("apse roof", [=](Emitter& em) {
        auto cone = [=](double u, double t) {
            return kApse + Dir(-90 + 180 * u) * (eave * (1 - t)) +
                   Vec3d(0, 0, kWallTop + pitch * t);
        };
        EmitSlateRoof(
            em, cone, kPi * eave, slope,
            [=](const Vec3d& p) { return p - Vec3d(kApse.x, 0, 20.0); }, d, 40);
        double r_low = kAmbulatory + kOuterWallT + 0.4, r_high = kArcadeY + kUpperWallT / 2;
        auto ring = [=](double u, double t) {
            return kApse + Dir(-90 + 180 * u) * (r_low + (r_high - r_low) * t) +
                   Vec3d(0, 0, kAisleWallTop + (19.5 - kAisleWallTop) * t);
        };
        EmitSlateRoof(
            em, ring, kPi * r_low, std::hypot(r_low - r_high, 19.5 - kAisleWallTop),
            [=](const Vec3d& p) { return p - Vec3d(kApse.x, 0, -10.0); }, d, 41);
    });
    return parts;
}

}  // namespace nave::preprocess::abbey
