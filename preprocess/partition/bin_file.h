#pragma once
// Temporary triangle bins: triangles appended in LZ4-compressed blocks to a file, read back in
// order. Each record is 40 bytes (9 floats + material and flags) plus 36 for normals and 24 for
// texture coordinates when present. Blocks: [u32 raw size][u32 compressed size][bytes]. LZ4 errors
// become Status.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/triangle_source.h"
#include "src/core/status.h"

namespace nave::preprocess {

class BinWriter {
  public:
    /// Creates (truncates) `path`. `block_bytes` is the uncompressed block size (memory held: about
    /// twice).
    static StatusOr<std::unique_ptr<BinWriter>> Create(const std::filesystem::path& path,
                                                       size_t block_bytes);
    ~BinWriter();

    Status Append(const Triangle& t);
    /// Writes the last block and closes the file.
    Status Close();

    uint64_t triangles() const { return triangles_; }
    uint64_t file_bytes() const { return file_bytes_; }
    const std::filesystem::path& path() const { return path_; }
    /// Memory held by the buffers.
    size_t MemoryBytes() const { return raw_.capacity() + compressed_.capacity(); }

  private:
    BinWriter(std::filesystem::path path, std::FILE* file, size_t block_bytes);
    Status FlushBlock();

    std::filesystem::path path_;
    std::FILE* file_ = nullptr;
    size_t block_bytes_;
    std::string raw_;
    std::vector<char> compressed_;
    uint64_t triangles_ = 0, file_bytes_ = 0;
};

class BinReader {
  public:
    static StatusOr<std::unique_ptr<BinReader>> Open(const std::filesystem::path& path);
    ~BinReader();
    /// Appends up to `max` triangles to `out`; returns false at the end.
    StatusOr<bool> Read(std::vector<Triangle>& out, size_t max);

  private:
    BinReader(std::filesystem::path path, std::FILE* file) : path_(std::move(path)), file_(file) {}
    Status NextBlock();

    std::filesystem::path path_;
    std::FILE* file_ = nullptr;
    std::string raw_;
    std::vector<char> compressed_;
    size_t pos_ = 0;
    uint64_t offset_ = 0;
};

/// Bytes one record takes in a bin (for estimates).
size_t BinRecordBytes(const Triangle& t);

}  // namespace nave::preprocess
