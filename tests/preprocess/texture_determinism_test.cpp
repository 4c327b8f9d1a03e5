// Preprocessing the same input twice gives the same bytes: the store and every file of its texture
// folder, names and contents. Once for the generated abbey, whose glass textures are written afresh
// into a temporary folder on every run, and once for a model whose texture file is written again
// between the runs (the same bytes, a later modification time). The runs are a second apart at
// least, so a time of writing or a modification time anywhere in the bytes shows.

#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "preprocess/preprocess.h"
#include "preprocess/texture_convert.h"
#include "src/core/file.h"
#include "src/imaging/image_io.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using Files = std::map<std::string, std::string>;  // file name -> bytes

std::string Bytes(const std::filesystem::path& path) {
    StatusOr<std::string> bytes = ReadFileToString(path);
    EXPECT_TRUE(bytes.ok()) << bytes.status().ToString();
    return bytes.ok() ? *bytes : std::string();
}

// Every file in `dir`, by name.
Files FilesIn(const std::filesystem::path& dir) {
    Files files;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        files[e.path().filename().string()] = Bytes(e.path());
    return files;
}

// Returns once the wall clock's second has changed, so that two runs around the call see
// different times (OpenEXR and TIFF dates have whole seconds).
void WaitForTheNextSecond() {
    const std::time_t now = std::time(nullptr);
    while (std::time(nullptr) == now) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

// Preprocesses `options` into "<dir>/s.nave" (the same file name in both directories: the store
// records its texture folder's name).
void PreprocessInto(PreprocessOptions options, const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    options.output = dir / "s.nave";
    options.threads = 2;
    options.memory_bytes = uint64_t(1) << 30;  // one brick's work beside the texture conversion
    StatusOr<PreprocessStats> stats = RunPreprocess(options);
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();
}

// The two stores and their texture folders are byte-identical, with `textures` files each.
void ExpectSameStoresAndTextures(const std::filesystem::path& a, const std::filesystem::path& b,
                                 size_t textures) {
    EXPECT_TRUE(Bytes(a / "s.nave") == Bytes(b / "s.nave")) << "the stores differ";
    const Files first = FilesIn(TextureFolderFor(a / "s.nave"));
    const Files second = FilesIn(TextureFolderFor(b / "s.nave"));
    EXPECT_EQ(first.size(), textures);
    ASSERT_EQ(second.size(), first.size());
    for (auto i = first.begin(), j = second.begin(); i != first.end(); ++i, ++j) {
        EXPECT_EQ(i->first, j->first);
        if (std::filesystem::path(i->first).extension() == ".tx") {
            // OpenImageIO 2.4's TIFF writer does not give the same bytes twice for the same pixels
            // (its compressed tiles vary in size from run to run); the name (the source's checksum,
            // which is what the store records) and every texel must still be the same.
            StatusOr<imaging::FloatImage> x =
                imaging::ReadImage(TextureFolderFor(a / "s.nave") / i->first);
            StatusOr<imaging::FloatImage> y =
                imaging::ReadImage(TextureFolderFor(b / "s.nave") / j->first);
            ASSERT_TRUE(x.ok() && y.ok());
            EXPECT_EQ(x->width, y->width);
            EXPECT_EQ(x->height, y->height);
            EXPECT_TRUE(x->pixels == y->pixels) << i->first << " has different texels";
            continue;
        }
        EXPECT_TRUE(i->second == j->second) << i->first << " and " << j->first << " differ";
    }
}

TEST(TextureDeterminism, GeneratedAbbeyGivesTheSameStoreAndTextures) {
    ::nave::test::ScratchDir dir = testing::MakeTempDir("texture_determinism_abbey");
    PreprocessOptions options;
    options.generate = "abbey:detail=0.01";
    PreprocessInto(options, dir / "a");
    WaitForTheNextSecond();
    PreprocessInto(options, dir / "b");
    ExpectSameStoresAndTextures(dir / "a", dir / "b", 5);  // the five glass colours
}

TEST(TextureDeterminism, ModelWithATextureFileGivesTheSameStoreAndTextures) {
    ::nave::test::ScratchDir dir = testing::MakeTempDir("texture_determinism_model");
    const std::filesystem::path model = dir / "model";
    std::filesystem::create_directories(model);
    {
        std::ofstream mtl(model / "tile.mtl");
        // One file in a colour slot (OpenEXR, sRGB decoded) and a data slot (TIFF, values kept).
        mtl << "newmtl tile\nKd 0.8 0.8 0.8\nmap_Kd tile.png\nmap_d tile.png\n";
        std::ofstream obj(model / "tile.obj");
        obj << "mtllib tile.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
               "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tile\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    }
    // 80 x 48 texels (MIP levels down to 1 x 1) of a pattern that differs in every channel.
    constexpr int kWidth = 80, kHeight = 48;
    std::vector<uint8_t> rgb(size_t(kWidth) * kHeight * 3);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            uint8_t* p = &rgb[(size_t(y) * kWidth + x) * 3];
            p[0] = uint8_t(x * 3);
            p[1] = uint8_t(y * 5);
            p[2] = uint8_t((x * y) % 251);
        }
    const std::filesystem::path png = model / "tile.png";
    ASSERT_TRUE(imaging::WriteRgb8(png, kWidth, kHeight, rgb, {}).ok());
    const std::string png_bytes = Bytes(png);

    PreprocessOptions options;
    options.inputs = {model / "tile.obj"};
    PreprocessInto(options, dir / "a");
    WaitForTheNextSecond();
    // The same bytes written again, as a checkout or a copy does: only the modification time moves.
    std::filesystem::remove(png);
    std::ofstream(png, std::ios::binary) << png_bytes;
    std::filesystem::last_write_time(
        png, std::filesystem::last_write_time(png) + std::chrono::seconds(10));
    PreprocessInto(options, dir / "b");
    ExpectSameStoresAndTextures(dir / "a", dir / "b", 2);
}

}  // namespace
}  // namespace nave::preprocess
