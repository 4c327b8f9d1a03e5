#include "src/core/file.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace nave {
namespace {

namespace fs = std::filesystem;

class FileTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("nave_file_test_" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    size_t EntriesInDir() const {
        return size_t(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
    }
    fs::path dir_;
};

TEST_F(FileTest, CommittedFileAppearsOnlyAfterCommit) {
    fs::path target = dir_ / "out.bin";
    auto file = AtomicFile::Create(target);
    ASSERT_TRUE(file.ok()) << file.status().ToString();
    ASSERT_TRUE(file->Write("hello world").ok());
    ASSERT_TRUE(file->WriteAt(0, "J", 1).ok());
    EXPECT_FALSE(fs::exists(target));
    EXPECT_EQ(file->size(), 11u);
    ASSERT_TRUE(file->Commit().ok());
    EXPECT_EQ(ReadFileToString(target).value(), "Jello world");
    EXPECT_EQ(EntriesInDir(), 1u);  // no temporary file left behind
}

TEST_F(FileTest, AbandonedFileLeavesNothing) {
    fs::path target = dir_ / "out.bin";
    {
        auto file = AtomicFile::Create(target);
        ASSERT_TRUE(file.ok());
        ASSERT_TRUE(file->Write("partial").ok());
    }
    EXPECT_FALSE(fs::exists(target));
    EXPECT_EQ(EntriesInDir(), 0u);
}

TEST_F(FileTest, CreateInMissingDirectoryNamesIt) {
    auto file = AtomicFile::Create(dir_ / "missing" / "out.bin");
    ASSERT_FALSE(file.ok());
    EXPECT_EQ(file.status().code(), StatusCode::kIoError);
    EXPECT_NE(file.status().message().find("missing"), std::string::npos);
}

TEST_F(FileTest, ShortReadIsDataLossWithOffset) {
    fs::path target = dir_ / "small.bin";
    auto file = AtomicFile::Create(target);
    ASSERT_TRUE(file->Write("0123456789").ok());
    ASSERT_TRUE(file->Commit().ok());
    auto reader = ReadOnlyFile::Open(target);
    ASSERT_TRUE(reader.ok());
    char buf[8];
    ASSERT_TRUE(reader->ReadAt(2, buf, 8).ok());
    EXPECT_EQ(std::string(buf, 8), "23456789");
    Status s = reader->ReadAt(6, buf, 8);
    EXPECT_EQ(s.code(), StatusCode::kDataLoss);
    EXPECT_NE(s.message().find("truncated"), std::string::npos);
    EXPECT_NE(s.message().find("offset 6"), std::string::npos);
    EXPECT_EQ(ReadOnlyFile::Open(dir_ / "nope").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace nave
