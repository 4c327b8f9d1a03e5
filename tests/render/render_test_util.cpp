#include "render_test_util.h"

#include <algorithm>
#include <cmath>

#include "src/core/check.h"
#include "src/render/bricks/memory_brick_source.h"

namespace nave::render::testing {

std::vector<store::MaterialRecord> NamedMaterials(const std::vector<std::string>& names) {
    std::vector<store::MaterialRecord> materials;
    for (const auto& name : names) {
        store::MaterialRecord r;
        r.name = name;
        materials.push_back(r);
    }
    return materials;
}

std::unique_ptr<BrickSource> GridSource(const store::BrickMesh& mesh,
                                        std::vector<store::MaterialRecord> materials, Vec3i cells) {
    auto device = EmbreeDevice::Create();
    EXPECT_TRUE(device.ok()) << device.status().ToString();
    if (!device.ok()) return nullptr;
    GridBricks grid = SplitIntoGridBricks(mesh, cells.x, cells.y, cells.z);
    return std::make_unique<MemoryBrickSource>(*device, std::move(grid.tree),
                                               std::move(grid.meshes), std::move(materials));
}

std::unique_ptr<BrickSource> GridSourceWithLevels(const store::BrickMesh& mesh,
                                                  std::vector<store::MaterialRecord> materials,
                                                  Vec3i cells, const store::LevelOptions& levels) {
    auto device = EmbreeDevice::Create();
    EXPECT_TRUE(device.ok()) << device.status().ToString();
    if (!device.ok()) return nullptr;
    GridBricks grid = SplitIntoGridBricks(mesh, cells.x, cells.y, cells.z);
    const std::vector<Bounds3f> brick_cells = grid.tree.BrickCells(uint32_t(grid.meshes.size()));
    std::vector<std::vector<store::BrickLevel>> coarser;
    for (size_t b = 0; b < grid.meshes.size(); ++b)
        coarser.push_back(store::MakeBrickLevels(grid.meshes[b], levels, &brick_cells[b]));
    return std::make_unique<MemoryBrickSource>(*device, std::move(grid.tree),
                                               std::move(grid.meshes), std::move(materials),
                                               std::move(coarser));
}

Status WriteGridBricksStore(const std::filesystem::path& path, const store::BrickMesh& mesh,
                            const std::vector<std::string>& names, Vec3i cells,
                            const store::EncodeOptions& options) {
    GridBricks grid = SplitIntoGridBricks(mesh, cells.x, cells.y, cells.z);
    store::GlobalGrid g;
    g.origin = Vec3d(-10, -10, -10);
    g.step = 1e-4;
    NAVE_ASSIGN_OR_RETURN(auto writer,
                          store::StoreWriter::Create(path, g, {{"test"}, "nave test", ""}));
    std::vector<Bounds3f> boxes = grid.tree.BrickCells(uint32_t(grid.meshes.size()));
    for (size_t b = 0; b < grid.meshes.size(); ++b) {
        NAVE_ASSIGN_OR_RETURN(store::EncodedBrick e,
                              store::EncodeBrick(grid.meshes[b], boxes[b], g, options));
        NAVE_ASSIGN_OR_RETURN(uint32_t id, writer->Append(e));
        NAVE_CHECK_EQ(id, uint32_t(b));
    }
    return writer->Finish(NamedMaterials(names), grid.tree, mesh.TriangleCount());
}

RenderResult TestScene::Run(const RunOptions& options) const {
    RenderResult r;
    r.film = std::make_unique<Film>(config.camera.width, config.camera.height, scene.output);
    r.status = RenderStreams(scene, r.film.get(), &r.stats, options.picker, options.paging,
                             options.session);
    return r;
}

namespace {

// Fills the scene part of `t` (BuildTestScene and BuildAndRender share it).
Status BuildInto(std::unique_ptr<BrickSource> source, SceneConfig config, TestScene* t) {
    t->source = std::move(source);
    t->config = std::move(config);
    NAVE_ASSIGN_OR_RETURN(t->scene, BuildRenderScene(t->config, *t->source));
    return Status::Ok();
}

}  // namespace

StatusOr<std::unique_ptr<TestScene>> BuildTestScene(std::unique_ptr<BrickSource> source,
                                                    SceneConfig config) {
    auto t = std::make_unique<TestScene>();
    NAVE_RETURN_IF_ERROR(BuildInto(std::move(source), std::move(config), t.get()));
    return t;
}

std::string ConfigError(const std::string& config_text, const std::string& file) {
    StatusOr<SceneConfig> c = ParseSceneConfig(config_text, file);
    return c.ok() ? std::string() : std::string(c.status().message());
}

std::string LampSceneError(const std::string& config_text, const std::string& file) {
    StatusOr<SceneConfig> config = ParseSceneConfig(config_text, file);
    EXPECT_TRUE(config.ok()) << config.status().message();
    if (!config.ok()) return std::string();
    StatusOr<std::unique_ptr<TestScene>> scene =
        BuildTestScene(GridSource(LampMesh(), NamedMaterials({"lamp"}), Vec3i(1, 1, 1)), *config);
    return scene.ok() ? std::string() : std::string(scene.status().message());
}

std::unique_ptr<TestRender> BuildAndRender(std::unique_ptr<BrickSource> source, SceneConfig config,
                                           const RunOptions& options) {
    EXPECT_TRUE(source != nullptr);
    if (source == nullptr) return nullptr;
    auto t = std::make_unique<TestRender>();
    Status built = BuildInto(std::move(source), std::move(config), t.get());
    EXPECT_TRUE(built.ok()) << built.ToString();
    if (!built.ok()) return nullptr;
    static_cast<RenderResult&>(*t) = t->Run(options);
    return t;
}

store::BrickMesh LampMesh() {
    store::BrickMesh m;
    AppendQuad(&m, {3, 0, 0}, {0, 0, 2}, {0, 2, 0}, 2, 0);
    return m;
}

store::BrickMesh FurnaceMesh() {
    store::BrickMesh m;
    AppendSphere(&m, {0, 0, 0}, 1.0f, 24, 48, 0, /*inward=*/true);
    return m;
}

std::unique_ptr<TestRender> Render(const store::BrickMesh& mesh,
                                   const std::vector<std::string>& material_names,
                                   const std::string& config_text, int n_split, int threads,
                                   Status* render_status) {
    auto config = ParseSceneConfig(config_text, "test.toml");
    EXPECT_TRUE(config.ok()) << config.status().ToString();
    if (!config.ok()) return nullptr;
    if (threads > 0) config->render.threads = threads;
    auto t = BuildAndRender(
        GridSource(mesh, NamedMaterials(material_names), Vec3i(n_split, n_split, n_split)),
        std::move(*config));
    if (t == nullptr) return nullptr;
    if (render_status != nullptr) {
        *render_status = t->status;
    } else {
        EXPECT_TRUE(t->status.ok()) << t->status.ToString();
    }
    return t;
}

double MaxRelativeDifference(const Film& a, const Film& b) {
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

double MeanY(const Film& film) {
    double sum = 0;
    for (size_t p = 0; p < film.pixel_count(); ++p) sum += film.PixelXYZ(uint32_t(p)).y;
    return sum / double(film.pixel_count());
}

SeedPair RenderSeedPair(const store::BrickMesh& mesh,
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

std::string SunSkyFloorAndBall() {
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

store::BrickMesh ClutterMesh() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 6, 0);
    AppendSphere(&m, {0.5f, 0.3f, 1.0f}, 0.8f, 16, 32, 1);
    AppendSphere(&m, {-1.5f, -1.0f, 0.6f}, 0.6f, 12, 24, 2);
    AppendBox(&m, Bounds3f({1.0f, -2.5f, 0.01f}, {2.5f, -1.2f, 1.8f}), 0);
    return m;
}

std::string ClutterScene(int width, int height) {
    return "[camera]\nposition = [6, 5, 3.5]\nlook_at = [0, 0, 0.6]\nfov_deg = 45\nresolution = [" +
           std::to_string(width) + ", " + std::to_string(height) + "]\n" + SunSkyFloorAndBall() +
           "[materials.chrome]\ntype = \"conductor\"\nroughness = 0.2\n";
}

store::BrickMesh RoomWithRoofWindow() {
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

std::string RoomWithRoofWindowScene() {
    return R"(
[camera]
position = [0.0, -1.8, 1.5]
look_at = [0.0, 0.0, 0.0]
up = [0, 0, 1]
fov_deg = 70
resolution = [24, 24]
)" + RoomWithRoofWindowSkyAndMaterials();
}

std::string RoomWithRoofWindowSkyAndMaterials() {
    return R"(
[sky]
radiance = 1.0
[materials.floor]
reflectance = 0.5
[materials.wall]
reflectance = 0.5
[materials.window]
type = "thin_dielectric"
eta = 1.5
portal = true
)";
}

}  // namespace nave::render::testing
