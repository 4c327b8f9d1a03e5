#pragma once
// Files written safely and read with errors that name them. Every output of nave goes through
// AtomicFile: written under a temporary name beside the target, fsynced and renamed only when
// complete, so that an interrupted or failed run never leaves a half-written file under the real
// name.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave {

/// Writes `path` atomically. Not thread-safe. Move-only.
class AtomicFile {
  public:
    /// Creates `<path>.tmp-<pid>-<n>` next to `path`. Errors name the directory (missing, not
    /// writable).
    static StatusOr<AtomicFile> Create(const std::filesystem::path& path);

    AtomicFile(AtomicFile&& other) noexcept;
    AtomicFile& operator=(AtomicFile&& other) noexcept;
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    /// Removes the temporary file if Commit() was not reached.
    ~AtomicFile();

    /// Appends bytes. A short write (full disk) is an IoError naming the file and the offset.
    Status Write(const void* data, size_t size);
    Status Write(std::string_view bytes) { return Write(bytes.data(), bytes.size()); }
    /// Overwrites bytes already written at `offset` (for headers patched at the end).
    Status WriteAt(uint64_t offset, const void* data, size_t size);
    /// Bytes written so far (the offset of the next Write).
    uint64_t size() const { return size_; }
    /// fsync: what was written is on the disk (a full disk that the writes did not report shows
    /// here), still under the temporary name. For files that must appear together: sync each,
    /// then commit each.
    Status Sync();
    /// fsync, rename to the final name, fsync the directory.
    Status Commit();
    /// Removes the temporary file now.
    void Abandon();

    const std::filesystem::path& path() const { return path_; }
    const std::filesystem::path& temp_path() const { return temp_path_; }

  private:
    AtomicFile(std::filesystem::path path, std::filesystem::path temp, int fd)
        : path_(std::move(path)), temp_path_(std::move(temp)), fd_(fd) {}
    std::filesystem::path path_;
    std::filesystem::path temp_path_;
    int fd_ = -1;
    uint64_t size_ = 0;
};

/// A file opened for positional reads (thread-safe: pread has no shared offset). Move-only.
class ReadOnlyFile {
  public:
    static StatusOr<ReadOnlyFile> Open(const std::filesystem::path& path);
    ReadOnlyFile(ReadOnlyFile&& other) noexcept;
    ReadOnlyFile& operator=(ReadOnlyFile&& other) noexcept;
    ReadOnlyFile(const ReadOnlyFile&) = delete;
    ReadOnlyFile& operator=(const ReadOnlyFile&) = delete;
    ~ReadOnlyFile();

    /// Reads exactly `size` bytes at `offset`; a short read is DataLoss ("truncated") naming file
    /// and offset.
    Status ReadAt(uint64_t offset, void* out, size_t size) const;
    uint64_t size() const { return size_; }
    const std::filesystem::path& path() const { return path_; }

  private:
    ReadOnlyFile(std::filesystem::path path, int fd, uint64_t size)
        : path_(std::move(path)), fd_(fd), size_(size) {}
    std::filesystem::path path_;
    int fd_ = -1;
    uint64_t size_ = 0;
};

/// fsyncs a file another writer (a library) wrote, before it is renamed into place. A full disk
/// that the writes did not report may show here as an IoError naming the file.
Status SyncFile(const std::filesystem::path& path);

/// Reads a whole (small) file into a string.
StatusOr<std::string> ReadFileToString(const std::filesystem::path& path);

}  // namespace nave
