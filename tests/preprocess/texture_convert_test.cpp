// Texture conversion at preprocess time: tiled MIP-mapped output, sRGB decoded for colour slots,
// content-addressed names whose checksum matches the file, missing textures dropped with a
// warning naming them.

#include "preprocess/texture_convert.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include "src/core/color.h"
#include "src/core/file.h"
#include "src/core/hash.h"

namespace nave::preprocess {
namespace {

class TextureConvertTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_texture_convert_test_" + std::to_string(getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_ / "model");
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // An 8-bit RGB TGA of 32 x 16 whose texels are (x * 8, y * 16, 128).
    void WriteTga(const std::filesystem::path& path) {
        std::vector<uint8_t> px(32 * 16 * 3);
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 32; ++x) {
                px[(y * 32 + x) * 3 + 0] = uint8_t(x * 8);
                px[(y * 32 + x) * 3 + 1] = uint8_t(y * 16);
                px[(y * 32 + x) * 3 + 2] = 128;
            }
        auto out = OIIO::ImageOutput::create(path.string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open(path.string(), OIIO::ImageSpec(32, 16, 3, OIIO::TypeUInt8)));
        ASSERT_TRUE(out->write_image(OIIO::TypeUInt8, px.data()));
        ASSERT_TRUE(out->close());
    }

    std::filesystem::path dir_;
};

TEST_F(TextureConvertTest, ConvertsToTiledMipmappedChecksummedFiles) {
    WriteTga(dir_ / "model" / "stone.tga");
    std::vector<store::MaterialRecord> materials(2);
    materials[0].name = "stone";
    materials[0].textures["map_Kd"] = "stone.tga";
    materials[0].textures["map_d"] = "stone.tga";  // the same file as data: a second conversion
    materials[1].name = "stone_copy";
    materials[1].textures["map_Kd"] = "stone.tga";
    std::filesystem::path store = dir_ / "out" / "m.nave";
    std::filesystem::create_directories(store.parent_path());
    StatusOr<TextureConvertStats> stats = ConvertTextures(&materials, {dir_ / "model"}, store);
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();
    EXPECT_EQ(stats->converted, 2u);
    EXPECT_EQ(stats->references, 3u);
    EXPECT_EQ(stats->dropped, 0u);
    EXPECT_TRUE(stats->warnings.empty());
    EXPECT_EQ(materials[0].textures["map_Kd"], materials[1].textures["map_Kd"]);

    const std::string colour = materials[0].textures["map_Kd"];
    std::smatch m;
    ASSERT_TRUE(
        std::regex_match(colour, m, std::regex(R"(m\.nave\.textures/stone\.([0-9a-f]{16})\.exr)")))
        << colour;
    std::filesystem::path file = store.parent_path() / colour;
    EXPECT_NE(materials[0].textures["map_d"].find("stone.data."), std::string::npos);
    // Named after the source and the conversion: preprocessing again into the same place gives the
    // same names and replaces the two files, with the same bytes, instead of adding two more, also
    // when the source was written again since (a later modification time).
    StatusOr<std::string> first_bytes = ReadFileToString(file);
    ASSERT_TRUE(first_bytes.ok()) << first_bytes.status().ToString();
    const auto tga = dir_ / "model" / "stone.tga";
    std::filesystem::last_write_time(
        tga, std::filesystem::last_write_time(tga) + std::chrono::seconds(10));
    std::vector<store::MaterialRecord> again(1);
    again[0].name = "stone";
    again[0].textures["map_Kd"] = "stone.tga";
    again[0].textures["map_d"] = "stone.tga";
    ASSERT_TRUE(ConvertTextures(&again, {dir_ / "model"}, store).ok());
    EXPECT_EQ(again[0].textures["map_Kd"], colour);
    EXPECT_EQ(again[0].textures["map_d"], materials[0].textures["map_d"]);
    StatusOr<std::string> again_bytes = ReadFileToString(file);
    ASSERT_TRUE(again_bytes.ok()) << again_bytes.status().ToString();
    EXPECT_TRUE(*again_bytes == *first_bytes) << file << " changed";
    size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(file.parent_path())) {
        ++files;
        (void)e;
    }
    EXPECT_EQ(files, 2u);

    auto in = OIIO::ImageInput::open(file.string());
    ASSERT_TRUE(in);
    OIIO::ImageSpec spec = in->spec();
    EXPECT_EQ(spec.tile_width, 64);
    EXPECT_EQ(spec.format, OIIO::TypeHalf);
    int levels = 0;
    while (in->seek_subimage(0, levels)) ++levels;
    EXPECT_EQ(levels, 6);  // 32x16, 16x8, 8x4, 4x2, 2x1, 1x1
    ASSERT_TRUE(in->seek_subimage(0, 0));
    std::vector<float> px(32 * 16 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeFloat, px.data()));
    // Texel (5, 3): encoded (40, 48, 128) / 255, decoded by IEC 61966-2-1, to half precision.
    const float* p = &px[(3 * 32 + 5) * 3];
    EXPECT_NEAR(p[0], SrgbDecode(40 / 255.0), 1e-3);
    EXPECT_NEAR(p[1], SrgbDecode(48 / 255.0), 1e-3);
    EXPECT_NEAR(p[2], SrgbDecode(128 / 255.0), 1e-3);
    // The data copy keeps the encoded values and the 8-bit type.
    auto data =
        OIIO::ImageInput::open((store.parent_path() / materials[0].textures["map_d"]).string());
    ASSERT_TRUE(data);
    EXPECT_EQ(data->spec().format, OIIO::TypeUInt8);
    ASSERT_TRUE(data->read_image(0, 0, 0, 3, OIIO::TypeFloat, px.data()));
    EXPECT_NEAR(px[(3 * 32 + 5) * 3], 40 / 255.0, 1e-6);
}

TEST_F(TextureConvertTest, MissingAndUnreadableTexturesFallBackWithOneWarningEach) {
    WriteTga(dir_ / "model" / "ok.tga");
    std::ofstream(dir_ / "model" / "broken.tga") << "not an image";
    std::vector<store::MaterialRecord> materials(3);
    materials[0].textures["map_Kd"] = "lost_fabric.tga";
    materials[1].textures["map_Kd"] = "lost_fabric.tga";
    materials[1].textures["bump"] = "broken.tga";
    materials[2].textures["map_Kd"] = "ok.tga";
    std::filesystem::path store = dir_ / "m.nave";
    StatusOr<TextureConvertStats> stats = ConvertTextures(&materials, {dir_ / "model"}, store);
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();
    ASSERT_EQ(stats->warnings.size(), 2u);
    int lost = 0, broken = 0;
    for (const std::string& w : stats->warnings) {
        lost += w.find("lost_fabric.tga") != std::string::npos;
        broken += w.find("broken.tga") != std::string::npos;
    }
    EXPECT_EQ(lost, 1);
    EXPECT_EQ(broken, 1);
    EXPECT_TRUE(materials[0].textures.empty());
    EXPECT_TRUE(materials[1].textures.empty());
    EXPECT_EQ(materials[2].textures.size(), 1u);
    EXPECT_EQ(stats->dropped, 3u);
}

TEST_F(TextureConvertTest, NoTexturesNoFolder) {
    std::vector<store::MaterialRecord> materials(1);
    StatusOr<TextureConvertStats> stats = ConvertTextures(&materials, {dir_}, dir_ / "m.nave");
    ASSERT_TRUE(stats.ok());
    EXPECT_FALSE(std::filesystem::exists(TextureFolderFor(dir_ / "m.nave")));
}

// A conversion killed outright leaves ".tmp-<pid>-<n>.exr" in the folder: the next run removes it
// when its process is gone, and keeps the converted textures and a running process's temporaries.
TEST_F(TextureConvertTest, StaleTemporariesOfKilledRunsAreRemoved) {
    const std::filesystem::path store = dir_ / "m.nave";
    const std::filesystem::path folder = TextureFolderFor(store);
    std::filesystem::create_directories(folder);
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    int status = 0;
    ::waitpid(child, &status, 0);
    const std::string dead = std::to_string(child), alive = std::to_string(::getppid());
    for (const std::string& name : {".tmp-" + dead + "-0.exr", ".tmp-" + dead + "-1.tx",
                                    ".tmp-" + alive + "-0.exr", std::string("wood.0123.exr")})
        std::ofstream(folder / name) << "x";
    RemoveStaleTextureTemporaries(store);
    EXPECT_FALSE(std::filesystem::exists(folder / (".tmp-" + dead + "-0.exr")));
    EXPECT_FALSE(std::filesystem::exists(folder / (".tmp-" + dead + "-1.tx")));
    EXPECT_TRUE(std::filesystem::exists(folder / (".tmp-" + alive + "-0.exr")));
    EXPECT_TRUE(std::filesystem::exists(folder / "wood.0123.exr"));
}

}  // namespace
}  // namespace nave::preprocess
