// Checkpoint files: round trip, and every kind of damage refused with a message naming the file
// and what differs.

#include "src/render/film/checkpoint.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "src/core/file.h"
#include "src/core/hash.h"

namespace nave::render {
namespace {

class CheckpointTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_checkpoint_test_" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir_);
        path_ = dir_ / "r.ckpt";
        checkpoint_.identity = Identity();
        checkpoint_.done = 7;
        checkpoint_.elapsed_seconds = 12.5;
        checkpoint_.sections["film"] = std::string("\x01\x02\x00\x03", 4);
        checkpoint_.sections["path_guide"] = std::string(1000, 'g');
        ASSERT_TRUE(WriteCheckpoint(path_, checkpoint_).ok());
        auto bytes = ReadFileToString(path_);
        ASSERT_TRUE(bytes.ok());
        bytes_ = *bytes;
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    static CheckpointIdentity Identity() {
        CheckpointIdentity id;
        id.model = 0x1234;
        id.config = 0xabcd;
        id.version = "1.2.3";
        id.mode = 1;
        id.model_name = "abbey.nave";
        id.config_name = "abbey.toml";
        return id;
    }
    /// Writes `bytes` as the checkpoint and reads it back.
    StatusOr<Checkpoint> ReadBack(const std::string& bytes) {
        std::ofstream(path_, std::ios::binary | std::ios::trunc) << bytes;
        return ReadCheckpoint(path_);
    }
    /// Rewrites the header checksum after an edit of the header, as a writer of another version
    /// would have made it.
    static void ResealHeader(std::string* bytes) {
        const uint64_t sum = Checksum64(bytes->data(), 32);
        std::memcpy(bytes->data() + 32, &sum, 8);
    }

    std::filesystem::path dir_, path_;
    Checkpoint checkpoint_;
    std::string bytes_;
};

TEST_F(CheckpointTest, RoundTrip) {
    auto read = ReadCheckpoint(path_);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    EXPECT_EQ(read->done, 7u);
    EXPECT_EQ(read->elapsed_seconds, 12.5);
    EXPECT_EQ(read->identity.model, 0x1234u);
    EXPECT_EQ(read->identity.config, 0xabcdu);
    EXPECT_EQ(read->identity.version, "1.2.3");
    EXPECT_EQ(read->identity.mode, 1);
    EXPECT_EQ(read->identity.model_name, "abbey.nave");
    EXPECT_EQ(read->sections, checkpoint_.sections);
    EXPECT_TRUE(CheckCheckpointIdentity(read->identity, Identity(), path_.string()).ok());
    // No temporary file is left beside it.
    int files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_)) files += e.is_regular_file();
    EXPECT_EQ(files, 1);
}

TEST_F(CheckpointTest, EveryTruncationIsRefusedNamingTheFile) {
    for (size_t size : {size_t(0), size_t(8), size_t(39), size_t(40), size_t(41), bytes_.size() / 2,
                        bytes_.size() - 1}) {
        auto read = ReadBack(bytes_.substr(0, size));
        ASSERT_FALSE(read.ok()) << size;
        EXPECT_EQ(read.status().code(), StatusCode::kDataLoss) << size;
        EXPECT_NE(read.status().message().find(path_.string()), std::string::npos)
            << read.status().message();
        if (size >= 40) {
            EXPECT_NE(read.status().message().find("truncated"), std::string::npos)
                << read.status().message();
        }
    }
}

TEST_F(CheckpointTest, AFlippedByteAnywhereIsRefused) {
    // Every byte of the header, and a sample of the body.
    for (size_t at = 0; at < bytes_.size(); at += at < 48 ? 1 : 97) {
        std::string bad = bytes_;
        bad[at] ^= 0x10;
        auto read = ReadBack(bad);
        ASSERT_FALSE(read.ok()) << "byte " << at;
        EXPECT_EQ(read.status().code(), StatusCode::kDataLoss) << at;
    }
    std::string bad = bytes_;
    bad[bytes_.size() - 3] ^= 1;
    auto read = ReadBack(bad);
    ASSERT_FALSE(read.ok());
    EXPECT_NE(read.status().message().find("checksum"), std::string::npos)
        << read.status().message();
}

TEST_F(CheckpointTest, NotACheckpointAndAppendedBytes) {
    auto read = ReadBack(std::string(100, 'x'));
    ASSERT_FALSE(read.ok());
    EXPECT_NE(read.status().message().find("not a nave checkpoint"), std::string::npos)
        << read.status().message();
    read = ReadBack(bytes_ + "more");
    ASSERT_FALSE(read.ok());
    EXPECT_NE(read.status().message().find("appended"), std::string::npos)
        << read.status().message();
}

TEST_F(CheckpointTest, AnotherMajorVersionIsUnsupportedNamingBoth) {
    std::string future = bytes_;
    const uint16_t major = kCheckpointMajor + 1;
    std::memcpy(future.data() + 8, &major, 2);
    ResealHeader(&future);
    auto read = ReadBack(future);
    ASSERT_FALSE(read.ok());
    EXPECT_EQ(read.status().code(), StatusCode::kUnsupported);
    EXPECT_NE(read.status().message().find("format " + std::to_string(major) + ".0"),
              std::string::npos)
        << read.status().message();
    EXPECT_NE(read.status().message().find("reads " + std::to_string(kCheckpointMajor) + ".x"),
              std::string::npos)
        << read.status().message();
}

TEST_F(CheckpointTest, IdentityMismatchSaysWhichDiffers) {
    const std::string file = path_.string();
    struct Case {
        void (*change)(CheckpointIdentity*);
        const char* says;
    };
    const Case cases[] = {
        {[](CheckpointIdentity* id) { id->version = "9.9.9"; },
         "written by nave 1.2.3, this is nave 9.9.9"},
        {[](CheckpointIdentity* id) { id->model = 1; }, "another model"},
        {[](CheckpointIdentity* id) { id->mode = 0; },
         "written in photon mode, this render is in path mode"},
        {[](CheckpointIdentity* id) { id->config = 2; }, "another config"},
    };
    for (const Case& c : cases) {
        CheckpointIdentity expected = Identity();
        c.change(&expected);
        Status s = CheckCheckpointIdentity(Identity(), expected, file);
        ASSERT_FALSE(s.ok()) << c.says;
        EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
        EXPECT_NE(s.message().find(c.says), std::string::npos) << s.message();
        EXPECT_NE(s.message().find(file), std::string::npos) << s.message();
    }
}

TEST_F(CheckpointTest, AMissingSectionIsNamed) {
    auto read = ReadCheckpoint(path_);
    ASSERT_TRUE(read.ok());
    auto section = read->Section("visible_points", path_.string());
    ASSERT_FALSE(section.ok());
    EXPECT_NE(section.status().message().find("no section visible_points"), std::string::npos)
        << section.status().message();
}

}  // namespace
}  // namespace nave::render
