#pragma once
// Building small scenes in memory for render tests: a mesh, split into a grid of bricks, plus a
// config.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "render/brick_source.h"
#include "render/film.h"
#include "render/grid_bricks.h"
#include "render/integrator.h"
#include "render/procedural_meshes.h"
#include "render/scene.h"
#include "render/scene_config.h"

namespace nave::render::testing {

struct TestRender {
    std::unique_ptr<MemoryBrickSource> source;
    SceneConfig config;
    RenderScene scene;
    std::unique_ptr<Film> film;
    RenderStats stats;
};

/// Splits `mesh` into n^3 bricks, parses `config_text`, renders. Material names:
/// material_names[id]. With `render_status`, the render's own Status goes there (for tests of its
/// errors) instead of being expected ok.
inline std::unique_ptr<TestRender> Render(const store::BrickMesh& mesh,
                                          const std::vector<std::string>& material_names,
                                          const std::string& config_text, int n_split,
                                          int threads = 0, Status* render_status = nullptr) {
    auto t = std::make_unique<TestRender>();
    auto device = EmbreeDevice::Create();
    EXPECT_TRUE(device.ok());
    GridBricks grid = SplitIntoGridBricks(mesh, n_split, n_split, n_split);
    std::vector<store::MaterialRecord> materials;
    for (const auto& name : material_names) {
        store::MaterialRecord r;
        r.name = name;
        materials.push_back(r);
    }
    t->source = std::make_unique<MemoryBrickSource>(*device, grid.tree, grid.meshes, materials);
    auto config = ParseSceneConfig(config_text, "test.toml");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    if (!config.ok()) return nullptr;
    t->config = *config;
    if (threads > 0) t->config.render.threads = threads;
    auto scene = BuildRenderScene(t->config, *t->source);
    EXPECT_TRUE(scene.ok()) << scene.status().ToString();
    if (!scene.ok()) return nullptr;
    t->scene = std::move(*scene);
    t->film =
        std::make_unique<Film>(t->config.camera.width, t->config.camera.height, t->scene.output);
    Status s = RenderStreams(t->scene, t->film.get(), &t->stats);
    if (render_status != nullptr) {
        *render_status = s;
    } else {
        EXPECT_TRUE(s.ok()) << s.ToString();
    }
    return t;
}

/// The largest per-channel difference of two films' pixels, relative to their sum (floored at
/// 1e-3).
inline double MaxRelativeDifference(const Film& a, const Film& b) {
    double worst = 0;
    for (size_t p = 0; p < a.pixel_count(); ++p) {
        Vec3d x = a.PixelXYZ(uint32_t(p)), y = b.PixelXYZ(uint32_t(p));
        for (int c = 0; c < 3; ++c) {
            double d = std::abs(x[c] - y[c]) / std::max(1e-3, std::abs(x[c]) + std::abs(y[c]));
            worst = std::max(worst, d);
        }
    }
    return worst;
}

/// The lights and two materials several test scenes share: sun and a faint uniform sky, a grey
/// floor and a ball whose reflectance rises from blue to red. No braces, so the text may go through
/// fmt.
inline std::string SunSkyFloorAndBall() {
    return R"(
[sun]
direction = [0.4, -0.5, 0.75]
[sky]
radiance = 0.05
[materials.floor]
reflectance = 0.7
[materials.ball.reflectance]
wavelengths_nm = [400, 550, 700]
values = [0.1, 0.5, 0.9]
)";
}

/// A floor, two balls and a box (materials "floor", "ball", "chrome").
inline store::BrickMesh ClutterMesh() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 6, 0);
    AppendSphere(&m, {0.5f, 0.3f, 1.0f}, 0.8f, 16, 32, 1);
    AppendSphere(&m, {-1.5f, -1.0f, 0.6f}, 0.6f, 12, 24, 2);
    AppendBox(&m, Bounds3f({1.0f, -2.5f, 0.01f}, {2.5f, -1.2f, 1.8f}), 0);
    return m;
}

/// ClutterMesh's camera (width x height), lights and materials, without a [render] table.
inline std::string ClutterScene(int width, int height) {
    return "[camera]\nposition = [6, 5, 3.5]\nlook_at = [0, 0, 0.6]\nfov_deg = 45\nresolution = [" +
           std::to_string(width) + ", " + std::to_string(height) + "]\n" + SunSkyFloorAndBall() +
           "[materials.chrome]\ntype = \"conductor\"\nroughness = 0.2\n";
}

/// Two renders that differ only in the seed: the mean luminance of both, the noise of one (the RMS
/// of their per-pixel difference over √2) and the second's statistics.
struct SeedPair {
    double mean = 0;
    double noise = 0;
    size_t pixels = 0;
    RenderStats stats;
};

/// Renders `config_text` (which must end inside its [render] table) with seeds 1 and 2, as Render
/// does with `n_split`.
inline SeedPair RenderSeedPair(const store::BrickMesh& mesh,
                               const std::vector<std::string>& material_names,
                               const std::string& config_text, int n_split) {
    std::vector<double> y[2];
    SeedPair pair;
    for (int seed = 0; seed < 2; ++seed) {
        auto t = Render(mesh, material_names,
                        config_text + "\nseed = " + std::to_string(seed + 1) + "\n", n_split);
        EXPECT_TRUE(t != nullptr);
        if (t == nullptr) return {};
        for (uint32_t p = 0; p < uint32_t(t->film->pixel_count()); ++p)
            y[seed].push_back(t->film->PixelXYZ(p).y);
        pair.stats = t->stats;
    }
    pair.pixels = y[0].size();
    double diff2 = 0;
    for (size_t p = 0; p < y[0].size(); ++p) {
        pair.mean += (y[0][p] + y[1][p]) / 2;
        diff2 += (y[0][p] - y[1][p]) * (y[0][p] - y[1][p]);
    }
    pair.mean /= double(pair.pixels);
    pair.noise = std::sqrt(diff2 / double(pair.pixels) / 2);
    return pair;
}

inline double MeanY(const Film& film) {
    double sum = 0;
    for (size_t p = 0; p < film.pixel_count(); ++p) sum += film.PixelXYZ(uint32_t(p)).y;
    return sum / double(film.pixel_count());
}

/// A 4 x 4 x 3 m closed room (materials: 0 floor, 1 walls and roof) with a 2 x 2 m window (material
/// 2) in the roof.
inline store::BrickMesh RoomWithRoofWindow() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {2, 0, 0}, {0, 2, 0}, 4, 0);        // floor, facing up
    AppendQuad(&m, {2, 0, 1.5f}, {0, 2, 0}, {0, 0, 1.5f}, 1, 1);  // walls
    AppendQuad(&m, {-2, 0, 1.5f}, {0, 0, 1.5f}, {0, 2, 0}, 1, 1);
    AppendQuad(&m, {0, 2, 1.5f}, {0, 0, 1.5f}, {2, 0, 0}, 1, 1);
    AppendQuad(&m, {0, -2, 1.5f}, {2, 0, 0}, {0, 0, 1.5f}, 1, 1);
    AppendQuad(&m, {1.5f, 0, 3}, {0.5f, 0, 0}, {0, 2, 0}, 1, 1);  // roof around a 2 x 2 m hole
    AppendQuad(&m, {-1.5f, 0, 3}, {0.5f, 0, 0}, {0, 2, 0}, 1, 1);
    AppendQuad(&m, {0, 1.5f, 3}, {1, 0, 0}, {0, 0.5f, 0}, 1, 1);
    AppendQuad(&m, {0, -1.5f, 3}, {1, 0, 0}, {0, 0.5f, 0}, 1, 1);
    AppendQuad(&m, {0, 0, 3}, {1, 0, 0}, {0, 1, 0}, 2, 2);  // the window
    return m;
}

}  // namespace nave::render::testing
