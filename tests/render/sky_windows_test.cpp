// The sky's windows chosen where they are seen (src/render/transport/sky_windows.h): portal
// triangles grouped into windows, per region a choice in proportion to the light the sky's photons
// brought through each, a sampled point's density as AreaDensity says, the learned sums the same
// whatever the order of the records and through a checkpoint.

#include "src/render/transport/sky_windows.h"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "render_test_util.h"
#include "src/render/transport/light_sampling.h"

namespace nave::render {
namespace {

/// Two 0.4 x 0.4 m windows (two triangles each) 20 m apart in a wall at y = 0, in a model 40 m
/// long: cells of 40 / 64 m, each window's triangles with their centroids in one cell.
struct TwoWindows {
    TwoWindows() {
        store::BrickMesh box;  // the model's bounds: 40 x 10 x 10 m
        box.positions = {{-20, -5, 0}, {20, 5, 10}, {20, -5, 0}};
        box.indices = {0, 1, 2};
        box.material_ids = {0};
        source = testing::GridSource(box, testing::NamedMaterials({"wall"}), {1, 1, 1});
        std::vector<std::array<Vec3f, 3>> triangles;
        for (float x0 : {-9.9f, 10.1f}) {
            const Vec3f a(x0, 0, 4), b(x0 + 0.4f, 0, 4), c(x0 + 0.4f, 0, 4.4f), d(x0, 0, 4.4f);
            triangles.push_back({a, b, c});
            triangles.push_back({a, c, d});
        }
        auto built = SkyPortals::Build(*source, std::move(triangles));
        EXPECT_TRUE(built.ok()) << built.status().ToString();
        portals = std::move(*built);
        windows = std::make_unique<SkyWindows>(*portals, source->bounds(), 1.0);
    }
    std::unique_ptr<BrickSource> source;
    std::unique_ptr<SkyPortals> portals;
    std::unique_ptr<SkyWindows> windows;
};

const Vec3f kInside(-9.5f, -3, 1);  // a point of the floor near the first window
constexpr int kUp = 4;              // PathGuide::SideOf(+z)

TEST(SkyWindows, TrianglesOfOneWindowGroupTogether) {
    TwoWindows w;
    EXPECT_EQ(w.windows->window_count(), 2u);
    EXPECT_EQ(PathGuide::SideOf(Vec3f(0, 0, 1)), kUp);
}

TEST(SkyWindows, ARegionChoosesWindowsInProportionToTheLightTheyBrought) {
    TwoWindows w;
    EXPECT_EQ(w.windows->Find(kInside, kUp), nullptr) << "nothing learned yet";
    // 30 photons through the first window (triangles 0 and 1), 10 through the second (2, 3), each
    // of power 1: the first brings three quarters.
    for (int i = 0; i < 30; ++i) w.windows->Record(kInside, kUp, uint32_t(i % 2), 1.0);
    for (int i = 0; i < 10; ++i) w.windows->Record(kInside, kUp, 2 + uint32_t(i % 2), 1.0);
    w.windows->Update();
    const SkyWindows::Region* region = w.windows->Find(kInside, kUp);
    ASSERT_NE(region, nullptr);
    EXPECT_EQ(w.windows->Find(kInside, 0), nullptr) << "another side is another region";
    // Per unit area: the window's probability over its 0.16 m^2.
    EXPECT_NEAR(w.windows->AreaDensity(*region, 0), 0.75 / 0.16, 1e-4);
    EXPECT_NEAR(w.windows->AreaDensity(*region, 1), 0.75 / 0.16, 1e-4);
    EXPECT_NEAR(w.windows->AreaDensity(*region, 3), 0.25 / 0.16, 1e-4);
    // Sampled points fall on the windows in those proportions, evenly over each window.
    int first = 0, lower_half = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
        const float u = (float(i) + 0.5f) / float(n);
        const Vec3f p = w.windows->SamplePoint(
            *region, u, Point2f(u * 7.f - float(int(u * 7.f)), u * 13.f - float(int(u * 13.f))));
        EXPECT_NEAR(p.y, 0.f, 1e-5f);
        EXPECT_GE(p.z, 4.f - 1e-5f);
        EXPECT_LE(p.z, 4.4f + 1e-5f);
        if (p.x < 0) {
            ++first;
            EXPECT_GE(p.x, -9.9f - 1e-5f);
            EXPECT_LE(p.x, -9.5f + 1e-5f);
            if (p.z < 4.2f) ++lower_half;
        }
    }
    EXPECT_NEAR(double(first) / n, 0.75, 0.01);
    EXPECT_NEAR(double(lower_half) / first, 0.5, 0.05);
}

TEST(SkyWindows, PhotonsAndShadowRaysTeachInTheirOwnUnits) {
    // Photons of typical power 1 and shadow-ray estimates of typical light 100: each kind of
    // record is counted against its own typical value, so 20 photons of power 1 through the first
    // window and 20 estimates of 100 through the second bring as much.
    TwoWindows w;
    SkyWindows windows(*w.portals, w.source->bounds(), 1.0, 100.0);
    for (int i = 0; i < 20; ++i) windows.Record(kInside, kUp, 0, 1.0);
    for (int i = 0; i < 20; ++i) windows.RecordEstimate(kInside, kUp, 2, 100.0);
    windows.Update();
    const SkyWindows::Region* region = windows.Find(kInside, kUp);
    ASSERT_NE(region, nullptr);
    EXPECT_NEAR(windows.AreaDensity(*region, 0), 0.5 / 0.16, 1e-4);
    EXPECT_NEAR(windows.AreaDensity(*region, 3), 0.5 / 0.16, 1e-4);
}

TEST(SkyWindows, TooFewPhotonsTeachNothing) {
    TwoWindows w;
    for (uint32_t i = 0; i + 1 < SkyWindows::kMinPhotons; ++i)
        w.windows->Record(kInside, kUp, 0, 1.0);
    w.windows->Update();
    EXPECT_EQ(w.windows->Find(kInside, kUp), nullptr);
    w.windows->Record(kInside, kUp, 0, 1.0);
    w.windows->Update();
    ASSERT_NE(w.windows->Find(kInside, kUp), nullptr);
    EXPECT_EQ(w.windows->AreaDensity(*w.windows->Find(kInside, kUp), 2), 0.f)
        << "a window no photon came through is not chosen";
}

TEST(SkyWindows, TheOrderOfRecordsAndACheckpointChangeNothing) {
    std::vector<std::array<double, 2>> records(200);  // (triangle, power)
    for (size_t i = 0; i < records.size(); ++i)
        records[i] = {double(i % 4), 0.1 + 0.37 * double(i % 11)};
    auto learned = [&](bool reversed) {
        TwoWindows w;
        for (size_t k = 0; k < records.size(); ++k) {
            const auto& r = records[reversed ? records.size() - 1 - k : k];
            w.windows->Record(kInside, kUp, uint32_t(r[0]), r[1]);
        }
        w.windows->Update();
        ByteWriter out;
        w.windows->SaveState(&out);
        return out.Take();
    };
    const std::string forward = learned(false);
    EXPECT_EQ(forward, learned(true));
    TwoWindows restored;
    ByteReader in(forward, "windows.ckpt");
    ASSERT_TRUE(restored.windows->LoadState(&in).ok());
    ByteWriter again;
    restored.windows->SaveState(&again);
    EXPECT_EQ(again.Take(), forward);
    ASSERT_NE(restored.windows->Find(kInside, kUp), nullptr);
}

TEST(SkyWindows, ACheckpointNamingAWindowThatDoesNotExistIsRefused) {
    TwoWindows w;
    ByteWriter out;
    out.Put(uint64_t(1));
    out.Put(uint64_t(7));  // region 0, window 7 of 2
    out.Put(uint64_t(100));
    out.Put(uint32_t(20));
    const std::string bytes = out.Take();
    ByteReader in(bytes, "windows.ckpt");
    const Status s = w.windows->LoadState(&in);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), StatusCode::kDataLoss);
    EXPECT_NE(s.message().find("windows.ckpt"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("window 7 of 2"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace nave::render
