// Textures in rendered images, attached as `nave render` does (AttachTextures): an albedo
// checkerboard lands at the right place on a rendered quad in both modes; an alpha-masked quad lets
// light through where alpha is 0, for camera rays and shadow rays; an emission texture emits its
// colours.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "render_test_util.h"
#include "src/core/color.h"
#include "src/core/file.h"
#include "src/imaging/texture_cache.h"
#include "src/render/scene/texture/surface_textures.h"

namespace nave::render {
namespace {

using namespace nave::imaging;

/// The scene of every test here (tests/fixtures/scenes/quad_under_sky.toml), as text to adapt.
std::string BaseConfig() {
    auto text =
        ReadFileToString(std::filesystem::path(NAVE_TEST_FIXTURES) / "scenes/quad_under_sky.toml");
    EXPECT_TRUE(text.ok()) << text.status().ToString();
    return text.ok() ? *text : std::string();
}

/// Writes a small float image with OpenImageIO (rows from the top).
void WriteImage(const std::filesystem::path& path, int w, int h, int channels,
                const std::vector<float>& px) {
    auto out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(path.string(), OIIO::ImageSpec(w, h, channels, OIIO::TypeFloat)));
    ASSERT_TRUE(out->write_image(OIIO::TypeFloat, px.data()));
    ASSERT_TRUE(out->close());
}

/// A 2 x 2 m quad at z = 0 facing up, OBJ texture coordinates (v up): (0, 0) at (-1, -1).
store::BrickMesh Quad() {
    store::BrickMesh m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material_ids = {0, 0};
    return m;
}

class TextureRenderTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_texture_render_test_" + std::to_string(getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
        // 2 x 2 texels, linear RGB: top-left and bottom-right red, the others blue.
        const float red[3] = {0.8f, 0.05f, 0.05f}, blue[3] = {0.05f, 0.05f, 0.8f};
        std::vector<float> px(12);
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c)
                px[size_t(i) * 3 + size_t(c)] = (i == 0 || i == 3) ? red[c] : blue[c];
        WriteImage(dir_ / "checker.exr", 2, 2, 3, px);
        // 2 x 1 grey mask: left half cut out (0), right half kept (1).
        WriteImage(dir_ / "mask.exr", 2, 1, 1, {0.f, 1.f});
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    /// Renders `mesh` (one material, `rec`) with `config_text`, its textures attached unless
    /// `textures` is false.
    std::unique_ptr<Film> Render(const store::BrickMesh& mesh, const store::MaterialRecord& rec,
                                 const std::string& config_text, bool textures = true) {
        auto source = testing::GridSource(mesh, {rec}, {1, 1, 1});
        EXPECT_TRUE(source && source->brick_count() == 1);
        if (source == nullptr) return nullptr;
        auto config = ParseSceneConfig(config_text, "t");
        EXPECT_TRUE(config.ok()) << config.status().ToString();
        if (!config.ok()) return nullptr;
        config->textures.enabled = textures;
        auto built = testing::BuildTestScene(std::move(source), std::move(*config));
        EXPECT_TRUE(built.ok()) << built.status().ToString();
        if (!built.ok()) return nullptr;
        testing::TestScene& t = **built;
        auto cache = TextureCache::Create(size_t(16) << 20);
        EXPECT_TRUE(cache.ok());
        std::vector<std::string> warnings;
        Status attached = AttachTextures(t.config, dir_, **cache, &t.scene, &warnings);
        EXPECT_TRUE(attached.ok()) << attached.ToString();
        EXPECT_TRUE(warnings.empty()) << warnings.front();
        EXPECT_EQ(t.scene.materials[0].textures != nullptr, textures);
        testing::RenderResult r = t.Run();
        EXPECT_TRUE(r.status.ok()) << r.status.ToString();
        // The one brick the render traced kept the mesh's texture coordinates.
        auto brick = t.source->Acquire(0);
        EXPECT_TRUE(brick.ok() && (*brick)->mesh().HasUvs());
        return std::move(r.film);
    }

    std::unique_ptr<Film> RenderQuad(bool textures, const std::string& extra_config = "") {
        store::MaterialRecord rec;
        rec.name = "checker";
        rec.textures["map_Kd"] = "checker.exr";
        return Render(Quad(), rec, BaseConfig() + extra_config, textures);
    }

    // Linear sRGB of the 3 x 3 pixels around (x, y) (row 0 at the top).
    static Vec3d Block(const Film& film, int x, int y) {
        Vec3d xyz;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
                xyz = xyz + film.PixelXYZ(uint32_t((y + dy) * film.width() + x + dx));
        return RgbColorSpace::Srgb().ToRgb(xyz * (1.0 / 9));
    }

    /// Red where the checker is red, blue elsewhere: pixels 5 and 26 of 32 look at x, y = -0.5 and
    /// +0.5 m, the centres of the four texels. Image top-left is world (-x, +y) = uv (0.25, 0.75) =
    /// texel (0, 0) (top-left of the image): red.
    static void ExpectChecker(const Film& film) {
        const struct {
            int x, y;
            bool red;
        } kSpots[] = {{5, 5, true}, {26, 5, false}, {5, 26, false}, {26, 26, true}};
        for (const auto& spot : kSpots) {
            Vec3d rgb = Block(film, spot.x, spot.y);
            if (spot.red) {
                EXPECT_GT(rgb.x, 4 * rgb.z)
                    << spot.x << "," << spot.y << ": " << rgb.x << " " << rgb.z;
            } else {
                EXPECT_GT(rgb.z, 4 * rgb.x)
                    << spot.x << "," << spot.y << ": " << rgb.x << " " << rgb.z;
            }
        }
    }

    std::filesystem::path dir_;
};

TEST_F(TextureRenderTest, CheckerboardLandsAtItsTextureCoordinates) {
    std::unique_ptr<Film> film = RenderQuad(true);
    ASSERT_TRUE(film);
    ExpectChecker(*film);
    // Without the texture the flat 0.5 material is neutral: every spot has the colour of the
    // equal-energy sky, whose linear sRGB is XYZ (1, 1, 1) through the IEC 61966-2-1 matrix.
    std::unique_ptr<Film> flat = RenderQuad(false);
    ASSERT_TRUE(flat);
    Vec3d a = Block(*flat, 5, 5), b = Block(*flat, 26, 5);
    EXPECT_NEAR(a.x / a.z, b.x / b.z, 0.1);
    Vec3d e = RgbColorSpace::Srgb().ToRgb(Vec3d(1, 1, 1));
    EXPECT_NEAR(a.x / a.z, e.x / e.z, 0.1);
}

// Textures are filtered over the pixel's footprint: a checkerboard of 512 x 512 texels alternating
// 0.05 and 0.95 (about 12 texels under each pixel here) renders like flat 0.5 with the same random
// numbers; bilinear point samples of the finest level would differ by tens of per cent per sample.
TEST_F(TextureRenderTest, FineTextureIsFilteredOverThePixelFootprint) {
    const int n = 512;
    std::vector<float> checker(size_t(n) * n * 3), grey(size_t(n) * n * 3, 0.5f);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            for (int c = 0; c < 3; ++c)
                checker[(size_t(y) * n + size_t(x)) * 3 + size_t(c)] = (x + y) % 2 ? 0.95f : 0.05f;
    WriteImage(dir_ / "fine.exr", n, n, 3, checker);
    WriteImage(dir_ / "grey.exr", n, n, 3, grey);
    store::MaterialRecord fine, flat;
    fine.name = flat.name = "m";
    fine.textures["map_Kd"] = "fine.exr";
    flat.textures["map_Kd"] = "grey.exr";
    // One sample per pixel, so that point samples would not average out.
    std::string config = BaseConfig();
    config.replace(config.find("spp = 16"), std::string("spp = 16").size(), "spp = 1");
    std::unique_ptr<Film> a = Render(Quad(), fine, config), b = Render(Quad(), flat, config);
    ASSERT_TRUE(a && b);
    double diff = 0, sum = 0;
    for (int y = 4; y < 28; ++y)
        for (int x = 4; x < 28; ++x) {
            const uint32_t p = uint32_t(y * 32 + x);
            diff += std::abs(a->PixelXYZ(p).y - b->PixelXYZ(p).y);
            sum += b->PixelXYZ(p).y;
        }
    EXPECT_LT(diff / sum, 0.05) << "mean relative difference per pixel";
}

// Photon mode: the camera's visible points see the texture (direct sky at the visible point, and
// photon deposits evaluated with the visible point's texture coordinates).
TEST_F(TextureRenderTest, CheckerboardInPhotonMode) {
    std::unique_ptr<Film> film =
        RenderQuad(true, "mode = \"photon\"\niterations = 2\nphotons_per_iteration = 20000\n");
    ASSERT_TRUE(film);
    ExpectChecker(*film);
}

// A black quad whose left half is cut out by map_d over a uniform sky: camera rays pass the cut
// half and see the sky (radiance 1), and stop on the kept half (black).
TEST_F(TextureRenderTest, AlphaMaskLetsTheSkyThroughWhereAlphaIsZero) {
    store::MaterialRecord rec;
    rec.name = "leaf";
    rec.textures["map_d"] = "mask.exr";
    std::string config = BaseConfig();
    config.replace(config.find("[materials.default]\nreflectance = 0.5"),
                   std::string("[materials.default]\nreflectance = 0.5").size(),
                   "[materials.default]\ntype = \"black\"");
    std::unique_ptr<Film> film = Render(Quad(), rec, config);
    ASSERT_TRUE(film);
    Vec3d cut = film->PixelXYZ(16 * 32 + 6), kept = film->PixelXYZ(16 * 32 + 25);
    EXPECT_NEAR(cut.y, 1.0, 0.05) << "the sky seen through the cut-out half";
    EXPECT_LT(kept.y, 1e-6) << "the black half stops the rays";
    // Without textures the whole quad is black.
    std::unique_ptr<Film> opaque = Render(Quad(), rec, config, /*textures=*/false);
    EXPECT_LT(opaque->PixelXYZ(16 * 32 + 6).y, 1e-6);
}

// Shadow rays obey the mask too: a ground quad under a masked occluder, lit by a light straight
// down, is lit under the cut half and in shadow under the kept half.
TEST_F(TextureRenderTest, AlphaMaskCastsShadowsOnlyWhereAlphaIsOne) {
    store::BrickMesh m = Quad();
    // The occluder: the same quad lifted to z = 0.5, material 1 (masked); the ground keeps material
    // 0.
    const uint32_t base = uint32_t(m.positions.size());
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(m.positions[size_t(i)] + Vec3f(0, 0, 0.5f));
        m.uvs.push_back(m.uvs[size_t(i)]);
    }
    for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + k);
    m.material_ids = {0, 0, 1, 1};
    store::MaterialRecord ground, leaf;
    ground.name = "ground";
    leaf.name = "leaf";
    leaf.textures["map_d"] = "mask.exr";
    auto grid_source = testing::GridSource(m, {ground, leaf}, {1, 1, 1});
    ASSERT_TRUE(grid_source != nullptr);
    BrickSource& source = *grid_source;
    auto cache = TextureCache::Create(size_t(16) << 20);
    ASSERT_TRUE(cache.ok());
    std::vector<std::string> warnings;
    auto mask = OpenSurfaceTextures(**cache, leaf, dir_, {}, &warnings);
    ASSERT_TRUE(mask && mask->alpha);
    source.SetAlphaMasks({nullptr, mask});
    auto brick = source.Acquire(0);
    ASSERT_TRUE(brick.ok()) << brick.status().ToString();
    const Vec3f down(0, 0, -1);
    // Under the cut half (x < 0) the first surface met from above is the ground; under the kept
    // half the leaf.
    BrickHit hit;
    ASSERT_TRUE((*brick)->Intersect(Vec3f(-0.5f, 0, 2), down, 0, 10, &hit));
    EXPECT_NEAR(hit.t, 2.f, 1e-4f);
    ASSERT_TRUE((*brick)->Intersect(Vec3f(0.5f, 0, 2), down, 0, 10, &hit));
    EXPECT_NEAR(hit.t, 1.5f, 1e-4f);
    // Shadow rays from the ground up to a light at z = 2.
    EXPECT_FALSE((*brick)->Occluded(Vec3f(-0.5f, 0, 0.01f), -down, 0, 1.9f));
    EXPECT_TRUE((*brick)->Occluded(Vec3f(0.5f, 0, 0.01f), -down, 0, 1.9f));
}

// An emission texture (map_Ke) emits its own colours, lifted as illuminant spectra, scaled by the
// config's emission_scale; no sky.
TEST_F(TextureRenderTest, EmissionTextureEmitsItsColours) {
    store::MaterialRecord rec;
    rec.name = "panel";
    rec.textures["map_Ke"] = "checker.exr";
    std::string config = BaseConfig();
    config.replace(config.find("[sky]\nradiance = 1.0\n"),
                   std::string("[sky]\nradiance = 1.0\n").size(), "");
    config.replace(config.find("reflectance = 0.5"), std::string("reflectance = 0.5").size(),
                   "reflectance = 0.0\nemission_scale = 2.0");
    std::unique_ptr<Film> film = Render(Quad(), rec, config);
    ASSERT_TRUE(film);
    ExpectChecker(*film);
    // RgbEmission keeps the texel's XYZ: red (0.8, 0.05, 0.05) x 2 has luminance 2 Y(red).
    const double y_red = RgbColorSpace::Srgb().ToXyz(Vec3d(0.8, 0.05, 0.05)).y * 2;
    Vec3d xyz;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            xyz = xyz + film->PixelXYZ(uint32_t((5 + dy) * 32 + 5 + dx));
    EXPECT_NEAR(xyz.y / 9, y_red, 0.05 * y_red);
}

// A thin glass pane whose internal transmittance is a spectral texture ("nave:transmittance", one
// channel per band): over a uniform sky, the left half (every band 1) passes the sky's grey; the
// right half (bands below 600 nm 0) passes only red.
TEST_F(TextureRenderTest, SpectralTransmittanceTextureColoursTheLightThroughAPane) {
    const std::vector<float> bands = {400, 450, 500, 550, 590, 610, 650, 700};
    std::vector<float> px;
    for (int x = 0; x < 2; ++x)
        for (float b : bands) px.push_back(x == 0 || b > 600 ? 1.f : 0.f);
    ASSERT_TRUE(WriteSpectralTexture(dir_ / "pane.exr", 2, 1, bands, px).ok());
    store::MaterialRecord rec;
    rec.name = "pane";
    rec.textures["nave:transmittance"] = "pane.exr";
    std::string config = BaseConfig();
    config.replace(config.find("reflectance = 0.5"), std::string("reflectance = 0.5").size(),
                   "type = \"thin_dielectric\"\neta = 1.5");
    std::unique_ptr<Film> film = Render(Quad(), rec, config);
    ASSERT_TRUE(film);
    Vec3d clear = Block(*film, 6, 16), red = Block(*film, 25, 16);
    // Clear glass at normal incidence passes (1 - R)^2 / (1 - R^2) = 92.3 % for eta 1.5 (R = 0.04).
    Vec3d sky = RgbColorSpace::Srgb().ToRgb(Vec3d(1, 1, 1));
    EXPECT_NEAR(clear.y / sky.y, 0.923, 0.03);
    EXPECT_NEAR(clear.x / clear.z, sky.x / sky.z, 0.1);
    EXPECT_GT(red.x, 4 * red.y) << red.x << " " << red.y;
    EXPECT_GT(red.x, 4 * red.z) << red.x << " " << red.z;
}

}  // namespace
}  // namespace nave::render
