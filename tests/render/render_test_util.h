#pragma once
// The render tests' one way to render: a brick source (a mesh split into bricks in memory, a store,
// a procedural model), a config, the scene built from both, and renders of it into fresh films with
// RenderStreams' options (brick order, paging, checkpoints). Also the scenes and measures several
// tests share.

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/bricks/grid_bricks.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_session.h"
#include "src/render/integrators/render_streams.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/scene_config.h"
#include "src/render/stream/pager.h"
#include "store/brick_levels.h"
#include "store/brick_mesh.h"
#include "store/material_record.h"
#include "store/store_writer.h"

namespace nave::render::testing {

// ----------------------------------------------------------------------------------------------
// Sources

/// White furnace: inside a closed sphere of albedo a whose surface emits Le, the radiance
/// everywhere is Le / (1 - a) (the Neumann series of the rendering equation, Kajiya 1986, with
/// constant L). With a = 0.5, Le = 0.5 (kFurnace): L = 1, and a constant spectrum of 1 has Y = 1
/// (CIE normalisation of SampledToXYZ). The unit sphere, material 0 ("shell"), seen from inside.
store::BrickMesh FurnaceMesh();
/// The furnace's config, its render mode ("path" or "photon") left as a fmt "{}"; it ends inside
/// [render].
inline constexpr const char* kFurnace = R"(
[camera]
position = [0.1, 0.05, 0.0]
look_at = [1, 0.2, 0.1]
fov_deg = 90
resolution = [16, 12]
[materials.shell]
reflectance = 0.5
emission = 0.5
[render]
mode = "{}"
spp = 64
iterations = 12
photons_per_iteration = 60000
max_depth = 64
seed = 3
)";

/// A lamp (a square of radiance 1, material 0 "lamp", black otherwise) 3 m down +x, filling the
/// narrow view of kLampConfig: what a medium between them does to it is all the image shows.
store::BrickMesh LampMesh();
/// LampMesh's config, path mode; it ends inside [render].
inline constexpr const char* kLampConfig = R"(
[camera]
position = [0, 0, 0]
look_at = [1, 0, 0]
fov_deg = 1
resolution = [8, 6]
[materials.lamp]
type = "black"
emission = 1
[render]
mode = "path"
spp = 4
max_depth = 4
)";

/// Material records named `names`, by material id; every other field at its default.
std::vector<store::MaterialRecord> NamedMaterials(const std::vector<std::string>& names);

/// `mesh` cut into cells.x * cells.y * cells.z bricks (SplitIntoGridBricks) held in memory, on a
/// fresh Embree device (a failure to create one fails the test and returns null).
std::unique_ptr<BrickSource> GridSource(const store::BrickMesh& mesh,
                                        std::vector<store::MaterialRecord> materials, Vec3i cells);

/// GridSource with each brick's coarser levels of detail (store::MakeBrickLevels with `levels`),
/// which renders use unless render.lod = "full".
std::unique_ptr<BrickSource> GridSourceWithLevels(const store::BrickMesh& mesh,
                                                  std::vector<store::MaterialRecord> materials,
                                                  Vec3i cells,
                                                  const store::LevelOptions& levels = {});

/// Writes `mesh` to a store at `path` cut as GridSource cuts it (every triangle in every cell its
/// box overlaps), each brick encoded with `options`, materials named `names`.
Status WriteGridBricksStore(const std::filesystem::path& path, const store::BrickMesh& mesh,
                            const std::vector<std::string>& names, Vec3i cells,
                            const store::EncodeOptions& options = {});

// ----------------------------------------------------------------------------------------------
// Scenes and renders

/// RenderStreams' arguments beyond the scene, film and statistics (render_streams.h): the defaults
/// render in-core with the pager's brick order.
struct RunOptions {
    BrickPicker picker;
    const PagerOptions* paging = nullptr;
    const SessionOptions* session = nullptr;
};

/// What one render made: its film (the camera's resolution), its statistics and its Status.
struct RenderResult {
    std::unique_ptr<Film> film;
    RenderStats stats;
    Status status;
};

/// A scene ready to render: the source, the config (as the scene was built from it) and the scene.
struct TestScene {
    std::unique_ptr<BrickSource> source;
    SceneConfig config;
    RenderScene scene;

    /// Renders the scene into a fresh film with `options`. The Status is returned, not expected.
    RenderResult Run(const RunOptions& options = {}) const;
};

/// Builds the scene of `config` over `source`. BuildRenderScene's errors come back (for tests of
/// them).
StatusOr<std::unique_ptr<TestScene>> BuildTestScene(std::unique_ptr<BrickSource> source,
                                                    SceneConfig config);

/// The error of parsing `config_text` as file `file` ("" if it parses).
std::string ConfigError(const std::string& config_text, const std::string& file);

/// The error of building a scene of LampMesh (one brick, material "lamp") from `config_text`, read
/// as file `file` ("" if it builds). A config that does not parse fails the test and gives "".
std::string LampSceneError(const std::string& config_text, const std::string& file);

/// A scene and its first render.
struct TestRender : TestScene, RenderResult {};

/// Builds the scene of `config` over `source` (expected to succeed: null if it does not) and
/// renders it once with `options`. The render's Status is kept in `status`, not expected.
std::unique_ptr<TestRender> BuildAndRender(std::unique_ptr<BrickSource> source, SceneConfig config,
                                           const RunOptions& options = {});

/// Splits `mesh` into n^3 bricks, parses `config_text` (with render.threads = `threads` if
/// positive), renders. Material names: material_names[id]. With `render_status`, the render's own
/// Status goes there (for tests of its errors) instead of being expected ok.
std::unique_ptr<TestRender> Render(const store::BrickMesh& mesh,
                                   const std::vector<std::string>& material_names,
                                   const std::string& config_text, int n_split, int threads = 0,
                                   Status* render_status = nullptr);

// ----------------------------------------------------------------------------------------------
// Measures

/// The largest per-channel difference of two films' pixels, relative to their sum (floored at
/// 1e-3).
double MaxRelativeDifference(const Film& a, const Film& b);

/// The mean luminance (Y) of a film's pixels.
double MeanY(const Film& film);

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
SeedPair RenderSeedPair(const store::BrickMesh& mesh,
                        const std::vector<std::string>& material_names,
                        const std::string& config_text, int n_split);

// ----------------------------------------------------------------------------------------------
// Shared scenes

/// The lights and two materials several test scenes share: sun and a faint uniform sky, a grey
/// floor and a ball whose reflectance rises from blue to red. No braces, so the text may go through
/// fmt.
std::string SunSkyFloorAndBall();

/// A floor, two balls and a box (materials "floor", "ball", "chrome").
store::BrickMesh ClutterMesh();

/// ClutterMesh's camera (width x height), lights and materials, without a [render] table.
std::string ClutterScene(int width, int height);

/// A 4 x 4 x 3 m closed room (materials: 0 floor, 1 walls and roof) with a 2 x 2 m window (material
/// 2) in the roof.
store::BrickMesh RoomWithRoofWindow();

/// RoomWithRoofWindow's camera (24 x 24), uniform sky and materials ("floor", "wall", and "window":
/// thin glass and a portal), without a [render] table.
std::string RoomWithRoofWindowScene();
/// RoomWithRoofWindowScene without its [camera] table.
std::string RoomWithRoofWindowSkyAndMaterials();

}  // namespace nave::render::testing
