#pragma once
// Forward-only buffered reading of a file of any size in bounded memory: lines (text formats, CRLF
// or LF) and raw bytes (binary formats), with the line number and byte offset that error messages
// need.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "src/core/status.h"

namespace nave::preprocess {

class StreamReader {
  public:
    /// Opens `path`. Errors: NotFound / IoError naming the path.
    static StatusOr<StreamReader> Open(const std::filesystem::path& path);
    StreamReader(StreamReader&& other) noexcept;
    StreamReader& operator=(StreamReader&& other) noexcept;
    StreamReader(const StreamReader&) = delete;
    StreamReader& operator=(const StreamReader&) = delete;
    ~StreamReader();

    /// Next line without its "\n" or "\r\n", valid until the next call. Returns false at the end of
    /// the file. Lines longer than 64 MiB are an error (a binary file read as text).
    StatusOr<bool> NextLine(std::string_view& line);
    /// Reads exactly `size` bytes; a short read is DataLoss naming the file, offset and sizes.
    Status ReadBytes(void* out, size_t size);
    /// Reads up to `size` bytes, returns how many (0 at the end).
    StatusOr<size_t> ReadSome(void* out, size_t size);

    /// 1-based number of the line last returned by NextLine.
    uint64_t line_number() const { return line_number_; }
    /// Offset of the next unread byte.
    uint64_t offset() const { return consumed_offset_; }
    uint64_t file_size() const { return file_size_; }
    /// "name.obj:123" for the line last returned.
    std::string Where() const;
    /// "name.ply @0x1a2b" at the current offset.
    std::string WhereOffset() const;
    const std::filesystem::path& path() const { return path_; }

  private:
    StreamReader(std::filesystem::path path, std::FILE* file, uint64_t size);
    Status Fill();  // moves the unread tail to the front and reads more

    std::filesystem::path path_;
    std::FILE* file_ = nullptr;
    uint64_t file_size_ = 0;
    std::vector<char> buffer_;
    size_t begin_ = 0, end_ = 0;  // unread bytes are buffer_[begin_, end_)
    bool eof_ = false;
    uint64_t consumed_offset_ = 0;
    uint64_t line_number_ = 0;
};

}  // namespace nave::preprocess
