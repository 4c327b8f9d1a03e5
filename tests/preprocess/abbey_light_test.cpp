// Daylight through the procedural abbey's clerestory: rays from the floor toward every clerestory
// window (nave, choir, transept, hemicycle) must reach its glass before any stone (the vaults'
// lateral cells rise round each window, the aisle roofs stay below the sills), and must cross
// exactly one glass surface on their way out (a pane is a single sheet: the renderer's thin-pane
// material accounts for both faces of the glass in one surface).

#include <embree3/rtcore.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "preprocess/abbey/abbey_source.h"

namespace nave::preprocess {
namespace {

constexpr double kPi = 3.14159265358979323846;

class AbbeyScene {
  public:
    explicit AbbeyScene(double detail) {
        auto source = MakeAbbeySource(detail);
        for (const auto& m : source->materials()) names_.push_back(m.name);
        std::vector<Triangle> batch;
        while (true) {
            auto more = source->Next(batch, 20000);
            EXPECT_TRUE(more.ok());
            if (!more.ok() || !*more) break;
            for (const Triangle& t : batch) {
                for (const Vec3f& p : t.p) verts_.insert(verts_.end(), {p.x, p.y, p.z});
                materials_.push_back(t.material);
            }
        }
        size_t n = materials_.size();
        device_ = rtcNewDevice(nullptr);
        scene_ = rtcNewScene(device_);
        RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, verts_.data(),
                                   0, 12, 3 * n);
        auto* index = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n));
        for (size_t i = 0; i < 3 * n; ++i) index[i] = unsigned(i);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene_, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(scene_);
    }
    ~AbbeyScene() {
        rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
    }

    /// The material name of the first hit beyond `tnear` along the ray ("" for the sky), and the
    /// hit distance.
    std::string Hit(const Vec3d& org, const Vec3d& dir, double tnear, double* t_hit) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh{};
        rh.ray.org_x = float(org.x);
        rh.ray.org_y = float(org.y);
        rh.ray.org_z = float(org.z);
        rh.ray.dir_x = float(dir.x);
        rh.ray.dir_y = float(dir.y);
        rh.ray.dir_z = float(dir.z);
        rh.ray.tnear = float(tnear);
        rh.ray.tfar = 1e30f;
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return "";
        *t_hit = rh.ray.tfar;
        return names_[materials_[rh.hit.primID]];
    }

  private:
    std::vector<std::string> names_;
    std::vector<float> verts_;
    std::vector<uint32_t> materials_;
    RTCDevice device_;
    RTCScene scene_;
};

bool IsGlass(const std::string& name) { return name.rfind("glass_", 0) == 0; }

/// A clerestory window (docs/abbey.md): a point of its glass plane `glass`, `outward` (unit,
/// horizontal), `along` the wall (unit, horizontal), its half width, sill and springing.
struct Window {
    std::string name;
    Vec3d glass, outward, along;
    double half_width, sill, spring;
};

std::vector<Window> ClerestoryWindows() {
    std::vector<Window> w;
    const Vec3d east(1, 0, 0), north(0, 1, 0);
    for (double s : {-1.0, 1.0}) {
        // Nave (8 bays of 7 m from x = 0) and choir (2 bays from x = 69): glass in the middle of
        // the 1.2 m upper walls whose inner faces are at |y| = 5.9.
        for (int b = 0; b < 8; ++b)
            w.push_back({"nave " + std::to_string(b), Vec3d(3.5 + 7 * b, s * 6.5, 0), north * s,
                         east, 1.3, 20.0, 23.6});
        for (int b = 0; b < 2; ++b)
            w.push_back({"choir " + std::to_string(b), Vec3d(72.5 + 7 * b, s * 6.5, 0), north * s,
                         east, 1.3, 20.0, 23.6});
        // Transept arms: west (x = 56) and east (x = 69) walls, windows at |y| = 16.5 and 23.5.
        for (double y : {16.5, 23.5}) {
            w.push_back({"transept west", Vec3d(55.4, s * y, 0), -east, north, 1.2, 19.0, 23.5});
            w.push_back({"transept east", Vec3d(69.6, s * y, 0), east, north, 1.2, 19.0, 23.5});
        }
    }
    // Hemicycle: five sides of 36 degrees round (83, 0), inner faces on the chords of radius 5.9.
    for (int k = 0; k < 5; ++k) {
        double a0 = (-90.0 + 36 * k) * kPi / 180, a1 = (-90.0 + 36 * (k + 1)) * kPi / 180;
        Vec3d p0(83 + 5.9 * std::cos(a0), 5.9 * std::sin(a0), 0);
        Vec3d p1(83 + 5.9 * std::cos(a1), 5.9 * std::sin(a1), 0);
        Vec3d mid = (p0 + p1) * 0.5;
        Vec3d out = Normalize(Vec3d(mid.x - 83, mid.y, 0));
        w.push_back({"hemicycle " + std::to_string(k), mid + out * 0.6, out, Normalize(p1 - p0),
                     0.55, 20.0, 23.8});
    }
    return w;
}

TEST(AbbeyLight, FloorSeesEveryClerestoryWindowThroughOnePane) {
    AbbeyScene scene(0.25);
    for (const Window& win : ClerestoryWindows()) {
        int through = 0;
        for (double floor_along : {-2.0, 0.0, 2.0}) {
            for (double floor_in : {7.0, 9.0}) {
                Vec3d org = win.glass - win.outward * floor_in + win.along * floor_along;
                org.z = 0.05;
                for (double target_along : {-0.5, 0.0, 0.5}) {
                    Vec3d target = win.glass + win.along * (target_along * win.half_width);
                    target.z = win.sill + 0.6 * (win.spring - win.sill);
                    Vec3d dir = Normalize(target - org);
                    double t = 0;
                    std::string first = scene.Hit(org, dir, 0, &t);
                    SCOPED_TRACE(win.name + " from (" + std::to_string(org.x) + ", " +
                                 std::to_string(org.y) + ") at z " + std::to_string(target.z));
                    if (first == "lead") continue;  // a came in the way: opaque, as it should be
                    if (!IsGlass(first)) {
                        ADD_FAILURE() << "the ray toward the window first hits '" << first
                                      << "' at " << org.z + dir.z * t << " m";
                        continue;
                    }
                    double t2 = 0;
                    std::string second = scene.Hit(org + dir * t, dir, 1e-3, &t2);
                    if (second == "lead") continue;  // the ray grazes a came beside the pane
                    // Or the window's own reveal or moulding, in the wall's thickness (0.6 m on
                    // the outer side of the glass, the moulding's roll 0.07 m beyond).
                    if (!second.empty() && Dot(dir * t2, win.outward) < 0.6 + 0.07 + 0.01) continue;
                    EXPECT_EQ(second, "") << "after its pane the ray hits '" << second << "' " << t2
                                          << " m further instead of leaving the church";
                    if (second.empty()) ++through;
                }
            }
        }
        EXPECT_GT(through, 0) << win.name << ": no ray from the floor gets through";
    }
}

TEST(AbbeyLight, SummerMorningSunReachesTheNaveFloor) {
    // The sun of configs/abbey.toml: 21 June 2025, 11:00 CEST at Royaumont (49.14 N, 2.38 E) stands
    // at azimuth 111.5 degrees (from north, clockwise), elevation 47.7 degrees (`nave sun`).
    const double az = 111.5 * kPi / 180, el = 47.7 * kPi / 180;
    const Vec3d sun(std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el));
    AbbeyScene scene(0.25);
    int lit = 0, two_panes = 0;
    // The nave's floor between the arcades, every 10 cm.
    for (int i = 10; i < 560; ++i) {
        for (int j = -55; j <= 55; ++j) {
            Vec3d org(0.1 * i, 0.1 * j, 0.05);
            double t = 0, t2 = 0;
            if (!IsGlass(scene.Hit(org, sun, 0, &t))) continue;
            std::string beyond = scene.Hit(org + sun * t, sun, 1e-3, &t2);
            if (IsGlass(beyond)) ++two_panes;
            if (beyond.empty()) ++lit;
        }
    }
    // Through the south clerestory (a lancet's glass is 2.6 m by 5.8 m; the splayed reveals let
    // a strip of it take this slanting sun) some square metres of the floor are in the sun.
    EXPECT_GT(lit, 50) << "no sunlight on the nave floor at 11:00";
    EXPECT_EQ(two_panes, 0) << "sunlight crosses two glass surfaces";
}

}  // namespace
}  // namespace nave::preprocess
