#include "store/spill_file.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <vector>

#include "common/file_size_limit.h"
#include "common/scratch_dir.h"

namespace nave::store {
namespace {

// One directory for the whole binary, removed at exit.
const std::filesystem::path& TestDir() {
    static const test::ScratchDir dir("spill_test");
    return dir.path();
}

std::vector<char> Noise(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<char> v(n);
    for (char& c : v) c = char(rng());
    return v;
}

TEST(SpillFile, RoundTripsCompressibleIncompressibleAndEmptyData) {
    auto file = SpillFile::Create(TestDir(), "test data");
    ASSERT_TRUE(file.ok()) << file.status().ToString();
    // Several chunks of repetitive data (compresses), noise (stored raw) and nothing.
    std::vector<char> repetitive(3 * SpillFile::kChunkBytes + 12345);
    for (size_t i = 0; i < repetitive.size(); ++i) repetitive[i] = char(i % 97);
    const std::vector<char> noise = Noise(SpillFile::kChunkBytes / 2 + 7, 1);
    const std::vector<char> empty;
    for (const std::vector<char>* data :
         std::vector<const std::vector<char>*>{&repetitive, &noise, &empty}) {
        auto extent = (*file)->Write(data->data(), data->size());
        ASSERT_TRUE(extent.ok()) << extent.status().ToString();
        EXPECT_EQ(extent->raw_bytes, data->size());
        std::vector<char> back(data->size(), 'x');
        ASSERT_TRUE((*file)->Read(*extent, back.data()).ok());
        EXPECT_EQ(back, *data);
    }
    const SpillStats s = (*file)->stats();
    EXPECT_EQ(s.raw_bytes_written, repetitive.size() + noise.size());
    // Repetitive data shrinks; noise is stored as it is, not larger.
    EXPECT_LT(s.stored_bytes_written, repetitive.size() / 10 + noise.size() + 1);
    EXPECT_GE(s.stored_bytes_written, noise.size());
}

TEST(SpillFile, ReleaseGivesTheSpaceBack) {
    auto file = SpillFile::Create(TestDir(), "test data");
    ASSERT_TRUE(file.ok());
    const std::vector<char> noise = Noise(2 * SpillFile::kChunkBytes, 2);
    auto a = (*file)->Write(noise.data(), noise.size());
    auto b = (*file)->Write(noise.data(), noise.size());
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ((*file)->stats().stored_bytes, 2 * noise.size());
    (*file)->Release(*a);
    EXPECT_EQ((*file)->stats().stored_bytes, noise.size());
    EXPECT_EQ((*file)->stats().peak_stored_bytes, 2 * noise.size());
    std::vector<char> back(noise.size());
    ASSERT_TRUE((*file)->Read(*b, back.data()).ok());  // the other extent is untouched
    EXPECT_EQ(back, noise);
}

TEST(SpillFile, LeavesNoFileInTheDirectory) {
    const std::filesystem::path dir = TestDir() / "empty";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    {
        auto file = SpillFile::Create(dir, "test data");
        ASSERT_TRUE(file.ok());
        const std::vector<char> noise = Noise(1000, 3);
        ASSERT_TRUE((*file)->Write(noise.data(), noise.size()).ok());
        EXPECT_TRUE(std::filesystem::is_empty(dir));
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(SpillFile, ChecksumMismatchIsDataLossNamingTheDirectory) {
    auto file = SpillFile::Create(TestDir(), "ray queues");
    ASSERT_TRUE(file.ok());
    const std::vector<char> noise = Noise(5000, 4);
    auto extent = (*file)->Write(noise.data(), noise.size());
    ASSERT_TRUE(extent.ok());
    extent->chunks[0].checksum ^= 1;  // what a flipped bit on disk looks like from here
    std::vector<char> back(noise.size());
    Status s = (*file)->Read(*extent, back.data());
    EXPECT_EQ(s.code(), StatusCode::kDataLoss);
    EXPECT_NE(s.message().find("ray queues"), std::string::npos) << s.ToString();
    EXPECT_NE(s.message().find(TestDir().string()), std::string::npos) << s.ToString();
    EXPECT_NE(s.message().find("checksum"), std::string::npos) << s.ToString();
}

TEST(SpillFile, MissingDirectoryIsNamed) {
    auto file = SpillFile::Create(TestDir() / "no" / "such" / "dir", "ray queues");
    ASSERT_FALSE(file.ok());
    EXPECT_EQ(file.status().code(), StatusCode::kIoError);
    EXPECT_NE(file.status().message().find("no/such/dir"), std::string::npos)
        << file.status().ToString();
}

TEST(SpillFile, AFullDiskIsAnErrorNamingTheDirectoryAndWhatWasSpilled) {
    // A file size limit makes writes past it fail as a full disk would (EFBIG instead of ENOSPC).
    auto file = SpillFile::Create(TestDir(), "ray queues");
    ASSERT_TRUE(file.ok());
    const std::vector<char> noise = Noise(256 << 10, 5);
    StatusOr<SpillExtent> extent = SpillExtent();
    {
        test::ScopedFileSizeLimit limit(64 << 10);
        ASSERT_TRUE(limit.ok());
        extent = (*file)->Write(noise.data(), noise.size());
    }
    ASSERT_FALSE(extent.ok());
    EXPECT_EQ(extent.status().code(), StatusCode::kIoError);
    EXPECT_NE(extent.status().message().find("ray queues"), std::string::npos)
        << extent.status().ToString();
    EXPECT_NE(extent.status().message().find(TestDir().string()), std::string::npos)
        << extent.status().ToString();
    EXPECT_EQ((*file)->stats().stored_bytes, 0u);
}

}  // namespace
}  // namespace nave::store
