// Textures in rendered images: an albedo checkerboard lands at the right place on a rendered quad.
// (The texture is attached to the scene by hand: `nave render` does not open textures yet.)

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "core/color.h"
#include "render/brick_source.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/scene.h"
#include "render/scene_config.h"
#include "render/texture/surface_textures.h"
#include "imaging/texture_cache.h"

namespace nave::render {
namespace {

using namespace nave::imaging;

constexpr const char* kConfig = R"(
[camera]
position = [0.0, 0.0, 2.0]
look_at = [0.0, 0.0, 0.0]
up = [0, 1, 0]
fov_deg = 40
resolution = [32, 32]
[sky]
radiance = 1.0
[materials.default]
reflectance = 0.5
[render]
spp = 16
max_depth = 1
seed = 5
)";

class TextureRenderTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_texture_render_test_" + std::to_string(getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
        // 2 x 2 texels, linear RGB: top-left and bottom-right red, the others blue.
        const float red[3] = {0.8f, 0.05f, 0.05f}, blue[3] = {0.05f, 0.05f, 0.8f};
        float px[12];
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c) px[i * 3 + c] = (i == 0 || i == 3) ? red[c] : blue[c];
        auto out = OIIO::ImageOutput::create((dir_ / "checker.exr").string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(
            out->open((dir_ / "checker.exr").string(), OIIO::ImageSpec(2, 2, 3, OIIO::TypeFloat)));
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, px));
        ASSERT_TRUE(out->close());
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // A 2 x 2 m quad at z = 0 facing up, OBJ texture coordinates (v up): (0, 0) at (-1, -1).
    std::unique_ptr<Film> RenderQuad(bool textures) {
        store::BrickMesh m;
        m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
        m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        m.indices = {0, 1, 2, 0, 2, 3};
        m.material_ids = {0, 0};
        store::MaterialRecord rec;
        rec.name = "checker";
        rec.textures["map_Kd"] = "checker.exr";
        auto device = EmbreeDevice::Create();
        EXPECT_TRUE(device.ok());
        GridBricks grid = SplitIntoGridBricks(m, 1, 1, 1);
        EXPECT_TRUE(grid.meshes.size() == 1 && grid.meshes[0].HasUvs());
        MemoryBrickSource source(*device, grid.tree, grid.meshes, {rec});
        auto config = ParseSceneConfig(kConfig, "t");
        EXPECT_TRUE(config.ok()) << config.status().ToString();
        if (!config.ok()) return nullptr;
        auto scene = BuildRenderScene(*config, source);
        EXPECT_TRUE(scene.ok()) << scene.status().ToString();
        if (!scene.ok()) return nullptr;
        auto cache = TextureCache::Create(size_t(16) << 20);
        EXPECT_TRUE(cache.ok());
        if (textures) {
            std::vector<std::string> warnings;
            scene->materials[0].albedo_texture = OpenSurfaceTextures(**cache, rec, dir_, &warnings);
            EXPECT_TRUE(scene->materials[0].albedo_texture != nullptr);
            EXPECT_TRUE(warnings.empty());
        }
        auto film =
            std::make_unique<Film>(config->camera.width, config->camera.height, config->output);
        RenderStats stats;
        Status s = RenderStreams(*scene, film.get(), &stats);
        EXPECT_TRUE(s.ok()) << s.ToString();
        return film;
    }

    // Linear sRGB of the 3 x 3 pixels around (x, y) (row 0 at the top).
    static Vec3d Block(const Film& film, int x, int y) {
        Vec3d xyz;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                xyz = xyz + film.PixelXYZ(uint32_t((y + dy) * film.width() + x + dx));
        return RgbColorSpace::Srgb().ToRgb(xyz * (1.0 / 9));
    }

    std::filesystem::path dir_;
};

TEST_F(TextureRenderTest, CheckerboardLandsAtItsTextureCoordinates) {
    std::unique_ptr<Film> film = RenderQuad(true);
    ASSERT_TRUE(film);
    // Pixels 5 and 26 of 32 look at x, y = -0.5 and +0.5 m: the centres of the four texels. Image
    // top-left is world (-x, +y) = uv (0.25, 0.75) = texel (0, 0) (top-left of the image): red.
    const struct {
        int x, y;
        bool red;
    } kSpots[] = {{5, 5, true}, {26, 5, false}, {5, 26, false}, {26, 26, true}};
    for (const auto& spot : kSpots) {
        Vec3d rgb = Block(*film, spot.x, spot.y);
        if (spot.red) {
            EXPECT_GT(rgb.x, 4 * rgb.z) << spot.x << "," << spot.y << ": " << rgb.x << " " << rgb.z;
        } else {
            EXPECT_GT(rgb.z, 4 * rgb.x) << spot.x << "," << spot.y << ": " << rgb.x << " " << rgb.z;
        }
    }
    // Without the texture the flat 0.5 material is neutral: every spot has the colour of the
    // equal-energy sky, whose linear sRGB is XYZ (1, 1, 1) through the IEC 61966-2-1 matrix.
    std::unique_ptr<Film> flat = RenderQuad(false);
    ASSERT_TRUE(flat);
    Vec3d a = Block(*flat, 5, 5), b = Block(*flat, 26, 5);
    EXPECT_NEAR(a.x / a.z, b.x / b.z, 0.1);
    Vec3d e = RgbColorSpace::Srgb().ToRgb(Vec3d(1, 1, 1));
    EXPECT_NEAR(a.x / a.z, e.x / e.z, 0.1);
}

}  // namespace
}  // namespace nave::render
