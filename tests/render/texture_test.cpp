// Image and spectral textures through the OpenImageIO-backed TextureCache: values at known
// coordinates, the memory cap, spectral band interpolation, errors.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "src/imaging/texture_cache.h"
#include "src/render/scene/texture/spectral_texture.h"

namespace nave::render {
namespace {

using namespace nave::imaging;

class TextureTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_texture_test_" + std::to_string(getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // Writes a float image; tiled when tile > 0.
    void WriteImage(const std::filesystem::path& path, int w, int h, int c,
                    const std::vector<float>& pixels, int tile = 0) {
        auto out = OIIO::ImageOutput::create(path.string());
        ASSERT_TRUE(out) << OIIO::geterror();
        OIIO::ImageSpec spec(w, h, c, OIIO::TypeFloat);
        spec.tile_width = tile;
        spec.tile_height = tile;
        ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
        ASSERT_TRUE(out->write_image(OIIO::TypeFloat, pixels.data())) << out->geterror();
        ASSERT_TRUE(out->close());
    }

    std::filesystem::path dir_;
};

TEST_F(TextureTest, CheckerboardReadsBackAtKnownCoordinates) {
    // 8 x 8 texels, texel (i, j) (column i, row j from the top) is red when i + j is even, blue
    // otherwise; the green channel holds the column index to pin the orientation.
    constexpr int kN = 8;
    std::vector<float> pixels(kN * kN * 3);
    for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i) {
            float* p = &pixels[(j * kN + i) * 3];
            bool even = (i + j) % 2 == 0;
            p[0] = even ? 1.f : 0.f;
            p[1] = float(i) / kN;
            p[2] = even ? 0.f : 1.f;
        }
    std::filesystem::path path = dir_ / "checker.exr";
    WriteImage(path, kN, kN, 3, pixels);
    auto cache = TextureCache::Create(16u << 20);
    ASSERT_TRUE(cache.ok()) << cache.status().ToString();
    StatusOr<TextureRef> tex = (*cache)->Open(path);
    ASSERT_TRUE(tex.ok()) << tex.status().ToString();
    EXPECT_EQ((*cache)->info(*tex).width, kN);
    EXPECT_EQ((*cache)->info(*tex).channels, 3);
    for (int j = 0; j < kN; ++j)
        for (int i = 0; i < kN; ++i) {
            float rgb[3];
            float s = (i + 0.5f) / kN, t = (j + 0.5f) / kN;
            ASSERT_TRUE((*cache)->Lookup(*tex, s, t, {}, 0, 3, rgb).ok());
            EXPECT_NEAR(rgb[0], pixels[(j * kN + i) * 3 + 0], 1e-5f) << i << "," << j;
            EXPECT_NEAR(rgb[1], pixels[(j * kN + i) * 3 + 1], 1e-5f) << i << "," << j;
            EXPECT_NEAR(rgb[2], pixels[(j * kN + i) * 3 + 2], 1e-5f) << i << "," << j;
        }
    // Halfway between two texel centres of a row, bilinear filtering gives the mean.
    float rgb[3];
    ASSERT_TRUE((*cache)->Lookup(*tex, 1.f / kN, 0.5f / kN, {}, 0, 3, rgb).ok());
    EXPECT_NEAR(rgb[0], 0.5f, 1e-5f);
    EXPECT_NEAR(rgb[1], 0.5f / kN, 1e-5f);
    // Repeat wrap: s + 1 is s.
    float wrapped[3];
    ASSERT_TRUE((*cache)->Lookup(*tex, 1.f + 2.5f / kN, 3.5f / kN, {}, 0, 3, wrapped).ok());
    EXPECT_NEAR(wrapped[1], 2.f / kN, 1e-5f);
    // A wide footprint averages the checker: half red, half blue.
    ASSERT_TRUE(
        (*cache)->Lookup(*tex, 0.5f, 0.5f, TextureFootprint::Isotropic(1.f), 0, 3, rgb).ok());
    EXPECT_NEAR(rgb[0], 0.5f, 0.05f);
    EXPECT_NEAR(rgb[2], 0.5f, 0.05f);
}

TEST_F(TextureTest, CacheStaysWithinItsCapOnMoreDataThanTheCap) {
    // Three 1024 x 1024 RGBA float textures (16 MiB each, 48 MiB in all) through a 10 MiB cache
    // (OpenImageIO's smallest). Every tile is read once; each texel value encodes its texture
    // and tile so that the values read back are checked too.
    constexpr int kSize = 1024, kTile = 64, kTextures = 3;
    constexpr size_t kCap = size_t(10) << 20;
    std::vector<std::filesystem::path> paths;
    for (int k = 0; k < kTextures; ++k) {
        std::vector<float> pixels(size_t(kSize) * kSize * 4);
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                float* p = &pixels[(size_t(y) * kSize + x) * 4];
                p[0] = float(k);
                const int tile_x = x / kTile, tile_y = y / kTile;
                p[1] = float(tile_x);
                p[2] = float(tile_y);
                p[3] = 1.f;
            }
        paths.push_back(dir_ / ("big" + std::to_string(k) + ".tif"));
        WriteImage(paths.back(), kSize, kSize, 4, pixels, kTile);
    }
    auto cache = TextureCache::Create(kCap);
    ASSERT_TRUE(cache.ok()) << cache.status().ToString();
    EXPECT_EQ((*cache)->max_memory_bytes(), kCap);
    size_t peak = 0;
    for (int k = 0; k < kTextures; ++k) {
        StatusOr<TextureRef> tex = (*cache)->Open(paths[k]);
        ASSERT_TRUE(tex.ok()) << tex.status().ToString();
        for (int ty = 0; ty < kSize / kTile; ++ty)
            for (int tx = 0; tx < kSize / kTile; ++tx) {
                float v[4];
                const int centre_x = tx * kTile + kTile / 2, centre_y = ty * kTile + kTile / 2;
                float s = (float(centre_x) + 0.5f) / kSize;
                float t = (float(centre_y) + 0.5f) / kSize;
                ASSERT_TRUE((*cache)->Lookup(*tex, s, t, {}, 0, 4, v).ok());
                ASSERT_EQ(v[0], float(k));
                ASSERT_EQ(v[1], float(tx));
                ASSERT_EQ(v[2], float(ty));
                peak = std::max(peak, (*cache)->memory_used_bytes());
            }
    }
    EXPECT_GE((*cache)->bytes_read(), uint64_t(kTextures) * kSize * kSize * 4 * 4 / 2)
        << "the textures were not read through the cache";
    // One tile of slack: the cache evicts after inserting.
    EXPECT_LE(peak, kCap + size_t(kTile) * kTile * 4 * 4) << (*cache)->StatsReport(2);
    EXPECT_GT(peak, kCap / 2);
}

TEST_F(TextureTest, SpectralTransmittanceFollowsItsBands) {
    // 4 bands at 400, 500, 600, 700 nm. Left half: passes blue (1, 1, 0, 0); right half: passes
    // red (0, 0, 1, 1).
    constexpr int kW = 64, kH = 64;
    const std::vector<float> bands = {400.f, 500.f, 600.f, 700.f};
    std::vector<float> pixels(kW * kH * 4);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            float* p = &pixels[(y * kW + x) * 4];
            bool left = x < kW / 2;
            p[0] = p[1] = left ? 1.f : 0.f;
            p[2] = p[3] = left ? 0.f : 1.f;
        }
    std::filesystem::path path = dir_ / "glass.exr";
    ASSERT_TRUE(WriteSpectralTexture(path, kW, kH, bands, pixels).ok());
    auto cache = TextureCache::Create(16u << 20);
    ASSERT_TRUE(cache.ok());
    StatusOr<SpectralTexture> glass = SpectralTexture::Open(**cache, path);
    ASSERT_TRUE(glass.ok()) << glass.status().ToString();
    ASSERT_EQ(glass->band_centres_nm().size(), 4u);
    EXPECT_NEAR(glass->band_centres_nm()[2], 600.f, 1e-3f);

    // Wavelengths 450, 550, 650, 380 nm: in a band pair, halfway, the other pair, before the first.
    // SampleUniform(u) gives lambda = lo + u (hi - lo) for the hero, rotated by 1/4 for the others.
    SampledWavelengths lambda = SampledWavelengths::SampleUniform(0.f, 350.f, 750.f);
    // 350, 450, 550, 650 nm.
    SampledSpectrum incident(2.f);
    StatusOr<SampledSpectrum> left = glass->Sample(0.25f, 0.5f, {}, lambda);
    StatusOr<SampledSpectrum> right = glass->Sample(0.75f, 0.5f, {}, lambda);
    ASSERT_TRUE(left.ok() && right.ok());
    SampledSpectrum out_left = incident * *left, out_right = incident * *right;
    const float expect_left[4] = {2.f, 2.f, 1.f, 0.f}, expect_right[4] = {0.f, 0.f, 1.f, 2.f};
    for (int i = 0; i < kNumWavelengths; ++i) {
        EXPECT_NEAR(out_left[i], expect_left[i], 1e-3f) << lambda[i] << " nm";
        EXPECT_NEAR(out_right[i], expect_right[i], 1e-3f) << lambda[i] << " nm";
    }
}

TEST_F(TextureTest, SpectralTextureNeedsOneBandCentrePerChannel) {
    std::filesystem::path plain = dir_ / "plain.exr";
    WriteImage(plain, 4, 4, 3, std::vector<float>(4 * 4 * 3, 0.5f));
    auto cache = TextureCache::Create(16u << 20);
    ASSERT_TRUE(cache.ok());
    StatusOr<SpectralTexture> t = SpectralTexture::Open(**cache, plain);
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.status().message().find("plain.exr"), std::string::npos) << t.status().ToString();
    EXPECT_NE(t.status().message().find(kBandCentresAttribute), std::string::npos);

    auto out = OIIO::ImageOutput::create((dir_ / "bad.exr").string());
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeFloat);
    spec.attribute(kBandCentresAttribute, "400,500");
    std::vector<float> px(4 * 4 * 3, 0.5f);
    ASSERT_TRUE(out->open((dir_ / "bad.exr").string(), spec) &&
                out->write_image(OIIO::TypeFloat, px.data()) && out->close());
    t = SpectralTexture::Open(**cache, dir_ / "bad.exr");
    ASSERT_FALSE(t.ok());
    EXPECT_NE(t.status().message().find("3 channels"), std::string::npos) << t.status().ToString();
}

TEST_F(TextureTest, MissingTextureIsOneErrorNamingIt) {
    auto cache = TextureCache::Create(16u << 20);
    ASSERT_TRUE(cache.ok());
    std::filesystem::path missing = dir_ / "sponza_missing_diffuse.tga";
    StatusOr<TextureRef> t = (*cache)->Open(missing);
    ASSERT_FALSE(t.ok());
    EXPECT_EQ(t.status().code(), StatusCode::kNotFound) << t.status().ToString();
    const std::string& msg = t.status().message();
    size_t first = msg.find("sponza_missing_diffuse.tga");
    ASSERT_NE(first, std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    // The next, unrelated error carries nothing of the first one (errors are taken, not left).
    std::filesystem::path garbage = dir_ / "garbage.png";
    std::ofstream(garbage) << "this is not a PNG";
    StatusOr<TextureRef> g = (*cache)->Open(garbage);
    ASSERT_FALSE(g.ok());
    EXPECT_EQ(g.status().code(), StatusCode::kIoError) << g.status().ToString();
    EXPECT_NE(g.status().message().find("garbage.png"), std::string::npos);
    EXPECT_EQ(g.status().message().find("sponza_missing_diffuse"), std::string::npos)
        << g.status().ToString();
}

TEST(TextureFootprintTest, RayConeWidthCarriedToTextureSpace) {
    // A 2 m x 2 m quad mapped once to [0, 1]²: 0.25 texture units per metre². A 1 cm wide cone
    // head on covers 0.01 * sqrt(1 / 4) = 0.005 texture units; at 60° it is twice as wide.
    TextureFootprint f = RayConeFootprint(0.01f, 1.f, 1.f, 4.f);
    EXPECT_NEAR(f.dsdx, 0.005f, 1e-7f);
    EXPECT_NEAR(f.dtdy, 0.005f, 1e-7f);
    EXPECT_EQ(f.dtdx, 0.f);
    EXPECT_NEAR(RayConeFootprint(0.01f, 0.5f, 1.f, 4.f).dsdx, 0.01f, 1e-7f);
    EXPECT_EQ(RayConeFootprint(10.f, 0.f, 1.f, 4.f).dsdx, 1.f);
    EXPECT_EQ(RayConeFootprint(0.01f, 1.f, 1.f, 0.f).dsdx, 0.f);
}

TEST(TextureBandsTest, InterpolatesAndHoldsEnds) {
    const float centres[] = {400.f, 500.f, 700.f};
    const float values[] = {0.2f, 0.6f, 1.0f};
    EXPECT_FLOAT_EQ(InterpolateBands(centres, values, 380.f), 0.2f);
    EXPECT_FLOAT_EQ(InterpolateBands(centres, values, 450.f), 0.4f);
    EXPECT_FLOAT_EQ(InterpolateBands(centres, values, 600.f), 0.8f);
    EXPECT_FLOAT_EQ(InterpolateBands(centres, values, 800.f), 1.0f);
}

}  // namespace
}  // namespace nave::render
