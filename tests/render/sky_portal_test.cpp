// Sky next-event estimation through portals (render.sky_sampling = "portals"): a closed room lit only by a
// uniform sky through a small window in its ceiling. Aiming sky samples at the window must give the same
// image in expectation as uniform directions (the estimator stays unbiased: MIS against BSDF sampling with the
// mixture pdf, Veach 1997) and less noise (most uniform directions hit the ceiling).

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "render/brick_source.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/scene.h"
#include "render/scene_config.h"

namespace nave::render {
namespace {

/// Adds the quad a b c d (counter-clockwise seen from its front) with material `m`.
void AddQuad(store::BrickMesh* mesh, Vec3f a, Vec3f b, Vec3f c, Vec3f d, uint32_t m) {
    const uint32_t base = uint32_t(mesh->positions.size());
    mesh->positions.insert(mesh->positions.end(), {a, b, c, d});
    mesh->indices.insert(mesh->indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    mesh->material_ids.insert(mesh->material_ids.end(), {m, m});
}

/// The room [-1, 1]² x [0, 2] with walls facing in (material 0) and a 0.4 x 0.4 m window of thin glass
/// (material 1, a portal) in the middle of its ceiling.
store::BrickMesh Room() {
    store::BrickMesh m;
    const float w = 0.2f;
    AddQuad(&m, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);      // floor, facing up
    AddQuad(&m, {-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2}, 0);    // west wall, facing +x
    AddQuad(&m, {1, -1, 0}, {1, -1, 2}, {1, 1, 2}, {1, 1, 0}, 0);        // east wall, facing -x
    AddQuad(&m, {-1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {1, -1, 0}, 0);    // south wall, facing +y
    AddQuad(&m, {-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}, 0);        // north wall, facing -y
    // The ceiling, facing down, around the window.
    AddQuad(&m, {-1, -1, 2}, {-1, 1, 2}, {-w, 1, 2}, {-w, -1, 2}, 0);
    AddQuad(&m, {w, -1, 2}, {w, 1, 2}, {1, 1, 2}, {1, -1, 2}, 0);
    AddQuad(&m, {-w, -1, 2}, {-w, -w, 2}, {w, -w, 2}, {w, -1, 2}, 0);
    AddQuad(&m, {-w, w, 2}, {-w, 1, 2}, {w, 1, 2}, {w, w, 2}, 0);
    AddQuad(&m, {-w, -w, 2}, {-w, w, 2}, {w, w, 2}, {w, -w, 2}, 1);      // the window
    return m;
}

constexpr const char* kConfig = R"(
[camera]
position = [0.0, -0.9, 1.0]
look_at = [0.0, 0.0, 0.0]
up = [0, 0, 1]
fov_deg = 70
resolution = [24, 24]
[sky]
radiance = 1.0
[materials.wall]
reflectance = 0.5
[materials.window]
type = "thin_dielectric"
eta = 1.5
portal = true
[render]
spp = 32
max_depth = 1
)";

/// The room split into n^3 bricks, with its two materials.
std::unique_ptr<MemoryBrickSource> RoomSource(int n) {
    auto device = EmbreeDevice::Create();
    EXPECT_TRUE(device.ok());
    GridBricks grid = SplitIntoGridBricks(Room(), n, n, n);
    store::MaterialRecord wall, window;
    wall.name = "wall";
    window.name = "window";
    return std::make_unique<MemoryBrickSource>(*device, grid.tree, grid.meshes,
                                               std::vector<store::MaterialRecord>{wall, window});
}

struct Result {
    double mean = 0;   ///< mean luminance over the image
    double noise = 0;  ///< RMS of the per-pixel difference between two seeds, over sqrt(2)
};

Result RenderRoom(const std::string& sky_sampling) {
    std::unique_ptr<MemoryBrickSource> source = RoomSource(2);
    auto config = ParseSceneConfig(std::string(kConfig) + "sky_sampling = \"" + sky_sampling + "\"\n", "room");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    std::vector<double> y[2];
    for (int seed = 0; seed < 2; ++seed) {
        config->render.seed = uint64_t(seed + 1);
        auto scene = BuildRenderScene(*config, *source);
        EXPECT_TRUE(scene.ok()) << scene.status().ToString();
        Film film(config->camera.width, config->camera.height, config->output);
        RenderStats stats;
        Status s = RenderStreams(*scene, &film, &stats);
        EXPECT_TRUE(s.ok()) << s.ToString();
        for (uint32_t p = 0; p < uint32_t(film.width() * film.height()); ++p) y[seed].push_back(film.PixelXYZ(p).y);
    }
    Result r;
    double diff2 = 0;
    for (size_t p = 0; p < y[0].size(); ++p) {
        r.mean += (y[0][p] + y[1][p]) / 2;
        diff2 += (y[0][p] - y[1][p]) * (y[0][p] - y[1][p]);
    }
    r.mean /= double(y[0].size());
    r.noise = std::sqrt(diff2 / double(y[0].size()) / 2);
    return r;
}

TEST(SkyPortals, SameImageInExpectationWithLessNoise) {
    const Result uniform = RenderRoom("uniform"), portals = RenderRoom("portals");
    ASSERT_GT(uniform.mean, 0);
    // Each mean averages 2 x 576 pixels x 32 paths; their difference stays within a few standard errors.
    const double tolerance = 4 * std::hypot(uniform.noise, portals.noise) / std::sqrt(2.0 * 576);
    EXPECT_NEAR(portals.mean, uniform.mean, tolerance) << "uniform noise " << uniform.noise << ", portals noise "
                                                      << portals.noise;
    EXPECT_LT(portals.noise, 0.5 * uniform.noise);
}

TEST(SkyPortals, PortalSamplingWithoutPortalsIsAnError) {
    std::string text = kConfig;
    text.replace(text.find("portal = true"), std::string("portal = true").size(), "");
    auto config = ParseSceneConfig(text + "sky_sampling = \"portals\"\n", "room");
    ASSERT_TRUE(config.ok()) << config.status().ToString();
    std::unique_ptr<MemoryBrickSource> source = RoomSource(1);
    auto scene = BuildRenderScene(*config, *source);
    ASSERT_TRUE(scene.ok());
    Film film(config->camera.width, config->camera.height, config->output);
    RenderStats stats;
    Status s = RenderStreams(*scene, &film, &stats);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("portal = true"), std::string::npos) << s.ToString();
}

}  // namespace
}  // namespace nave::render
