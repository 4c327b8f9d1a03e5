// Media whose density is an OpenVDB grid (scene/media/vdb_density.h through the plugin of
// src/volumes/vdb_plugin.h): exact integrals over voxels, the same image as the box it stands for,
// and files that are not what they should be, named.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "render_test_util.h"
#include "src/core/color.h"
#include "src/core/progress.h"
#include "src/render/bricks/memory_brick_source.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/bricks/vdb_density.h"

namespace nave::render {
namespace {

namespace fs = std::filesystem;
using testing::MeanY;
using testing::Render;

class VdbMediumTest : public ::testing::Test {
  protected:
    void SetUp() override {
        ProgressBar::SetEnabled(false);
        dir_ = fs::temp_directory_path() / ("nave_vdb_" + std::to_string(getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    /// Writes a grid of `dims` voxels of 0.5 m from `origin` with `value` to `name`.vdb.
    fs::path Write(const std::string& name, const Vec3f& origin, const Vec3i& dims,
                   const std::function<float(int, int, int)>& value) {
        StatusOr<const volumes::VdbPlugin*> plugin = volumes::LoadVdbPlugin();
        EXPECT_TRUE(plugin.ok()) << plugin.status().message();
        fs::path path = dir_ / (name + ".vdb");
        if (plugin.ok()) {
            const Status written =
                (*plugin)->WriteScalarGrid(path, "density", origin, 0.5f, dims, value);
            EXPECT_TRUE(written.ok()) << written.message();
        }
        return path;
    }
    fs::path dir_;
};

// A ray along x through voxels of densities 1, 2, 3, 4 (0.5 m each): ∫ = 0.5 (1 + 2 + 3 + 4) = 5;
// the integral reaches 2 a quarter of the way into the third voxel (0.5 + 1 = 1.5 before it,
// 0.5 more at density 3 takes 1/6 m).
TEST_F(VdbMediumTest, IntegralsAreExactSumsOverTheVoxels) {
    const fs::path file =
        Write("ramp", {0, 0, 0}, {4, 2, 2}, [](int i, int, int) { return float(i + 1); });
    StatusOr<std::shared_ptr<const VdbDensity>> density = VdbDensity::Load(file, "density", 1.f);
    ASSERT_TRUE(density.ok()) << density.status().message();
    const VdbDensity& d = **density;
    EXPECT_NEAR(d.bounds().min.x, 0.f, 1e-6f);
    EXPECT_NEAR(d.bounds().max.x, 2.f, 1e-6f);
    EXPECT_NEAR(d.bounds().max.z, 1.f, 1e-6f);
    const Vec3f o(-1, 0.4f, 0.6f), x(1, 0, 0);
    EXPECT_NEAR(d.Integral(o, x, 0, 100.f), 5.f, 1e-5f);
    EXPECT_NEAR(d.Integral(o, x, 0, 1.75f), 0.5f * 1 + 0.25f * 2, 1e-5f);  // ends inside voxel 1
    EXPECT_NEAR(d.Reach(o, x, 0, 100.f, 2.f), 1.f + 1.f + 1.f / 6.f, 1e-5f);
    EXPECT_TRUE(std::isinf(d.Reach(o, x, 0, 100.f, 5.5f)));
    EXPECT_EQ(d.Integral(Vec3f(-1, 5, 0.5f), x, 0, 100.f), 0.f);  // beside the grid
    // density_scale multiplies the values.
    StatusOr<std::shared_ptr<const VdbDensity>> doubled = VdbDensity::Load(file, "density", 2.f);
    ASSERT_TRUE(doubled.ok());
    EXPECT_NEAR((*doubled)->Integral(o, x, 0, 100.f), 10.f, 1e-5f);
    // A diagonal ray: the sum over the voxels it crosses equals the integral of the ramp along it.
    const Vec3f diag = Normalize(Vec3f(1, 0.3f, 0.1f));
    const Vec3f start(-0.5f, 0.2f, 0.3f);
    double expected = 0;
    const int steps = 200000;
    for (int s = 0; s < steps; ++s) {
        const float t = (s + 0.5f) * 4.f / steps;
        const Vec3f p = start + diag * t;
        if (p.x >= 0 && p.x < 2 && p.y >= 0 && p.y < 1 && p.z >= 0 && p.z < 1)
            expected += (std::floor(p.x / 0.5f) + 1) * 4.0 / steps;
    }
    EXPECT_NEAR(d.Integral(start, diag, 0, 4.f), expected, 1e-3);
}

// A grid of density 1 filling a box gives the box medium's image.
TEST_F(VdbMediumTest, AGridOfDensityOneRendersAsTheBoxItFills) {
    const fs::path file = Write("slab", {1, -1, -1}, {2, 4, 4}, [](int, int, int) { return 1.f; });
    const store::BrickMesh mesh = testing::LampMesh();
    const std::string config = testing::kLampConfig;
    const auto box = Render(mesh, {"lamp"},
                            config +
                                "[medium]\nbox_min = [1, -1, -1]\nbox_max = [2, 1, 1]\n"
                                "sigma_a = 0.7\nsigma_s = 0.3\n",
                            2);
    const auto grid = Render(
        mesh, {"lamp"},
        config + "[medium]\ngrid = \"" + file.string() + "\"\nsigma_a = 0.7\nsigma_s = 0.3\n", 2);
    ASSERT_TRUE(box && grid);
    EXPECT_GT(MeanY(*box->film), 0.0);
    EXPECT_LT(testing::MaxRelativeDifference(*box->film, *grid->film), 1e-4);
}

// Dust over the clutter scene: the same image with 1 brick on one thread and 64 bricks on two.
TEST_F(VdbMediumTest, AHeterogeneousGridRendersTheSameImageWithOneAnd64Bricks) {
    // Inside the model's box (a stored grid keeps only what lies in the bricks' cells).
    const fs::path file = Write("puffs", {-4, -4, 0}, {16, 16, 3}, [](int i, int j, int k) {
        const float x = (i - 8) / 8.f, y = (j - 8) / 8.f, z = k / 3.f;
        return std::max(0.f, 1.f - (x * x + y * y + z * z)) * (1 + (i + j + k) % 3);
    });
    const std::string config = testing::ClutterScene(32, 24) + R"(
[render]
mode = "path"
spp = 4
seed = 11
[medium]
grid = ")" + file.string() + R"("
sigma_s = 0.6
sigma_a = 0.1
g = 0.3
)";
    auto one = Render(testing::ClutterMesh(), {"floor", "ball", "chrome"}, config, 1, 1);
    auto many = Render(testing::ClutterMesh(), {"floor", "ball", "chrome"}, config, 4, 2);
    ASSERT_TRUE(one && many);
    EXPECT_GT(many->stats.brick_moves, 0u);
    EXPECT_GT(MeanY(*one->film), 0.0);
    // A ray's flight is summed brick by brick: the bricks' sums round apart from one brick's in the
    // last bits of a float, and nothing more.
    EXPECT_LT(testing::MaxRelativeDifference(*one->film, *many->film), 1e-5);

    // The grid cut into 16 bricks (columns, none empty), each holding its own share of it (grid =
    // "store"): the same image again.
    StatusOr<std::shared_ptr<const VdbDensity>> whole = VdbDensity::Load(file, "density", 1.f);
    ASSERT_TRUE(whole.ok()) << whole.status().message();
    std::string held = config;
    held.replace(held.find("grid = \""), held.find("sigma_s") - held.find("grid = \""),
                 "grid = \"store\"\n");
    StatusOr<SceneConfig> parsed = ParseSceneConfig(held, "held.toml");
    ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
    parsed->render.threads = 2;
    std::unique_ptr<BrickSource> source = testing::GridSource(
        testing::ClutterMesh(), testing::NamedMaterials({"floor", "ball", "chrome"}), {4, 4, 1});
    static_cast<MemoryBrickSource&>(*source).HoldMedium(*whole);
    auto in_bricks = testing::BuildAndRender(std::move(source), std::move(*parsed));
    ASSERT_TRUE(in_bricks);
    ASSERT_TRUE(in_bricks->status.ok()) << in_bricks->status.ToString();
    EXPECT_LT(testing::MaxRelativeDifference(*one->film, *in_bricks->film), 1e-5);
}

// A slab 1 m thick of absorbing gas at 2000 K (a temperature grid, its own density: values 2000
// times density_scale 0.001 = 2 m^-1 with σa = 1), in front of the lamp (radiance 1): it glows at
// Planck's radiance B(λ, 2000 K) as far as it is opaque, L = B (1 - e^-2) + e^-2 (Kirchhoff's
// law in the radiative transfer equation without scattering; Planck's law, CODATA 2018).
TEST_F(VdbMediumTest, HotGasGlowsAtPlancksRadianceAsFarAsItIsOpaque) {
    const float kelvin = 2000.f;
    const fs::path file =
        Write("hot", {1, -1, -1}, {2, 4, 4}, [&](int, int, int) { return kelvin; });
    std::string config = testing::kLampConfig;
    config.replace(config.find("spp = 4"), 7, "spp = 64");
    const auto t = Render(testing::LampMesh(), {"lamp"},
                          config + "[medium]\ngrid = \"" + file.string() +
                              "\"\ndensity_scale = 0.001\nsigma_a = 1\n"
                              "temperature_grid = \"density\"\n",
                          2);
    ASSERT_TRUE(t);
    const double planck_y = SpectrumToXYZ(Spectrum::FromFunction([&](double nm) {
                                return PlanckRadiance(nm, kelvin);
                            })).y;
    const double expected = planck_y * (1 - std::exp(-2.0)) + std::exp(-2.0);
    EXPECT_GT(planck_y, 1.0);  // brighter than the lamp: the glow is what the image shows
    EXPECT_NEAR(MeanY(*t->film), expected, 0.015 * expected);
}

// Glowing dust over the clutter scene (emission scaled by the dust's own grid): the points along
// a ray where the emission is looked at are fixed by the ray, not the bricks, so 1 brick and 64
// give the same image.
TEST_F(VdbMediumTest, AGlowingGridRendersTheSameImageWithOneAnd64Bricks) {
    const fs::path file = Write("glow", {-4, -4, 0}, {16, 16, 3}, [](int i, int j, int k) {
        return (i + j + k) % 4 == 0 ? 0.f : 0.3f * float(1 + (i * j + k) % 3);
    });
    const std::string config = testing::ClutterScene(32, 24) + R"(
[render]
mode = "path"
spp = 4
seed = 5
[medium]
grid = ")" + file.string() + R"("
sigma_s = 0.4
sigma_a = 0.3
emission = 0.8
emission_grid = "density"
)";
    auto one = Render(testing::ClutterMesh(), {"floor", "ball", "chrome"}, config, 1, 1);
    auto many = Render(testing::ClutterMesh(), {"floor", "ball", "chrome"}, config, 4, 2);
    ASSERT_TRUE(one && many);
    EXPECT_GT(many->stats.brick_moves, 0u);
    // The glow is part of the image: without it the image is darker.
    std::string dark_config = config;
    dark_config.erase(dark_config.find("emission = 0.8"));
    auto dark = Render(testing::ClutterMesh(), {"floor", "ball", "chrome"}, dark_config, 1, 1);
    ASSERT_TRUE(dark);
    EXPECT_GT(MeanY(*one->film), 1.05 * MeanY(*dark->film));
    EXPECT_LT(testing::MaxRelativeDifference(*one->film, *many->film), 1e-4);
}

TEST_F(VdbMediumTest, FilesThatAreNotDensityGridsAreNamed) {
    const fs::path good = Write("good", {0, 0, 0}, {2, 2, 2}, [](int, int, int) { return 1.f; });
    auto error = [](const fs::path& file, const std::string& grid = "density") {
        StatusOr<std::shared_ptr<const VdbDensity>> d = VdbDensity::Load(file, grid, 1.f);
        return d.ok() ? std::string() : std::string(d.status().message());
    };
    EXPECT_EQ(error(good), "");
    EXPECT_NE(error(good, "smoke").find("no grid 'smoke' (grids there: density)"),
              std::string::npos);
    const fs::path text = dir_ / "text.vdb";
    std::ofstream(text) << "not a grid\n";
    EXPECT_NE(error(text).find(text.string() + ": not a readable OpenVDB file"), std::string::npos);
    // Cut short: the first half of a good file.
    const fs::path cut = dir_ / "cut.vdb";
    fs::copy_file(good, cut);
    fs::resize_file(cut, fs::file_size(good) / 2);
    EXPECT_NE(error(cut).find(cut.string()), std::string::npos) << error(cut);
    EXPECT_NE(error(dir_ / "missing.vdb").find("no such file"), std::string::npos);
    const fs::path negative = Write("negative", {0, 0, 0}, {2, 2, 2},
                                    [](int i, int, int) { return i == 1 ? -1.f : 1.f; });
    EXPECT_NE(error(negative).find("density -1 at voxel (1, "), std::string::npos)
        << error(negative);
}

TEST(VdbMediumConfigTest, AGridAndABoxAreRefusedTogether) {
    auto error = [](const std::string& medium) {
        return testing::ConfigError(
            "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[medium]\nsigma_s = 0.1\n" +
                medium + "\n",
            "dir/haze.toml");
    };
    EXPECT_NE(error("grid = \"dust.vdb\"\nbox_min = [0, 0, 0]\nbox_max = [1, 1, 1]")
                  .find("a grid or a box"),
              std::string::npos);
    EXPECT_NE(error("grid_name = \"smoke\"").find("need a grid"), std::string::npos);
    StatusOr<SceneConfig> ok = ParseSceneConfig(
        "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[medium]\nsigma_s = 0.1\ngrid = "
        "\"dust.vdb\"\ngrid_name = \"smoke\"\ndensity_scale = 3\n",
        "dir/haze.toml");
    ASSERT_TRUE(ok.ok()) << ok.status().message();
    EXPECT_EQ(ok->medium->grid, fs::path("dir/dust.vdb"));  // beside the config
    EXPECT_EQ(ok->medium->grid_name, "smoke");
    EXPECT_EQ(ok->medium->density_scale, 3.f);
}

}  // namespace
}  // namespace nave::render
