// Images and converted textures on a full disk: the write that fails must be an error naming the
// file, whatever buffer of the writer it falls in, and a set of images is written whole or not at
// all. A file size limit (test::ScopedFileSizeLimit) stands for the full disk; a limit one byte
// short of a file's size catches a writer that flushes its last buffer without checking.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/file_size_limit.h"
#include "common/list_names.h"
#include "common/scratch_dir.h"
#include "src/imaging/image_io.h"
#include "src/imaging/make_texture.h"

namespace nave::imaging {
namespace {

/// A 96x64 image of varied values, so that its compressed file is tens of kilobytes.
FloatImage VariedImage() {
    FloatImage image;
    image.width = 96;
    image.height = 64;
    image.channels = {"R", "G", "B"};
    image.pixels.resize(size_t(image.width) * image.height * 3);
    uint32_t state = 12345;
    for (float& v : image.pixels) {
        state = state * 1664525u + 1013904223u;  // Numerical Recipes' LCG: values, not statistics
        v = float(state >> 8) / float(1u << 24);
    }
    return image;
}

std::string Contents(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ImageWrite, AnExrOneByteShortOfItsSizeIsAnError) {
    const test::ScratchDir dir("image_write_short");
    const FloatImage image = VariedImage();
    ASSERT_TRUE(WriteExr(dir / "whole.exr", image, {}).ok());
    const uintmax_t size = std::filesystem::file_size(dir / "whole.exr");
    ASSERT_GT(size, 8192u);
    Status st;
    {
        test::ScopedFileSizeLimit limit(size - 1);
        ASSERT_TRUE(limit.ok());
        st = WriteExr(dir / "short.exr", image, {});
    }
    EXPECT_EQ(st.code(), StatusCode::kIoError) << st.ToString();
    EXPECT_NE(st.message().find((dir / "short.exr").string()), std::string::npos) << st.ToString();
    EXPECT_EQ(test::ListNames(dir.path()), std::vector<std::string>{"whole.exr"});
}

TEST(ImageWrite, ASetIsWrittenWholeOrLeavesWhatWasThere) {
    const test::ScratchDir dir("image_write_set");
    std::ofstream(dir / "a.exr", std::ios::binary) << "old exr";
    std::ofstream(dir / "a.png", std::ios::binary) << "old png";
    // The first file fits under the limit, the second does not.
    const std::vector<EncodedImage> images = {
        {dir / "a.exr", std::vector<unsigned char>(1000, 'e')},
        {dir / "a.png", std::vector<unsigned char>(100000, 'p')}};
    Status st;
    {
        test::ScopedFileSizeLimit limit(50000);
        ASSERT_TRUE(limit.ok());
        st = WriteImages(images);
    }
    EXPECT_EQ(st.code(), StatusCode::kIoError) << st.ToString();
    EXPECT_NE(st.message().find((dir / "a.png").string()), std::string::npos) << st.ToString();
    EXPECT_EQ(Contents(dir / "a.exr"), "old exr");
    EXPECT_EQ(Contents(dir / "a.png"), "old png");
    EXPECT_EQ(test::ListNames(dir.path()), (std::vector<std::string>{"a.exr", "a.png"}));

    ASSERT_TRUE(WriteImages(images).ok());
    EXPECT_EQ(Contents(dir / "a.exr"), std::string(1000, 'e'));
    EXPECT_EQ(Contents(dir / "a.png"), std::string(100000, 'p'));
    EXPECT_EQ(test::ListNames(dir.path()), (std::vector<std::string>{"a.exr", "a.png"}));
}

TEST(ImageWrite, ATextureOneByteShortOfItsSizeIsAnError) {
    const test::ScratchDir dir("texture_write_short");
    ASSERT_TRUE(WriteExr(dir / "source.exr", VariedImage(), {}).ok());
    ASSERT_TRUE(
        MakeTiledTexture(dir / "source.exr", dir / "whole.tx.exr", TextureContent::kData).ok());
    const uintmax_t size = std::filesystem::file_size(dir / "whole.tx.exr");
    Status st;
    {
        test::ScopedFileSizeLimit limit(size - 1);
        ASSERT_TRUE(limit.ok());
        st = MakeTiledTexture(dir / "source.exr", dir / "short.tx.exr", TextureContent::kData);
    }
    EXPECT_EQ(st.code(), StatusCode::kIoError) << st.ToString();
    EXPECT_NE(st.message().find((dir / "short.tx.exr").string()), std::string::npos)
        << st.ToString();
}

}  // namespace
}  // namespace nave::imaging
