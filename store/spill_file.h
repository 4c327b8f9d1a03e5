#pragma once
// Scratch space on disk for what a memory budget cannot hold (docs/pager.md, "Spilling"): data
// written once in LZ4-compressed, checksummed chunks and read back whole. The file never has a name
// in the directory (O_TMPFILE, or unlinked right after creation), so it disappears when the process
// ends, whether the run succeeds, fails or is killed; space given back with Release is returned to
// the file system at once (hole punching where the file system supports it).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "src/core/status.h"

namespace nave::store {

/// One compressed chunk of an extent, as written.
struct SpillChunk {
    uint64_t offset = 0;    ///< first byte in the file
    uint32_t stored = 0;    ///< bytes in the file (== raw: stored uncompressed)
    uint32_t raw = 0;       ///< bytes it decompresses to
    uint64_t checksum = 0;  ///< XXH64 of the stored bytes
};

/// Where one SpillFile::Write put its data; read it back with SpillFile::Read.
struct SpillExtent {
    std::vector<SpillChunk> chunks;
    uint64_t raw_bytes = 0;     ///< bytes given to Write
    uint64_t stored_bytes = 0;  ///< bytes it takes in the file
};

/// What a spill file did so far.
struct SpillStats {
    uint64_t raw_bytes_written = 0;
    uint64_t stored_bytes_written = 0;
    uint64_t raw_bytes_read = 0;
    uint64_t stored_bytes = 0;  ///< bytes written and not released
    uint64_t peak_stored_bytes = 0;
};

/// A scratch file of compressed extents. Thread-safe: Write, Read and Release may be called from
/// any thread at once.
class SpillFile {
  public:
    /// Uncompressed bytes per chunk: the memory a Write or Read holds beside its caller's data.
    static constexpr size_t kChunkBytes = size_t(1) << 20;

    /// Creates the file in `dir` (which must exist). `purpose` names what is spilled in messages
    /// ("ray queues"). Errors name the directory.
    static StatusOr<std::unique_ptr<SpillFile>> Create(const std::filesystem::path& dir,
                                                       std::string purpose);
    ~SpillFile();
    SpillFile(const SpillFile&) = delete;
    SpillFile& operator=(const SpillFile&) = delete;

    /// Appends `size` bytes. A failed write (full disk, file too large) is an IoError naming the
    /// directory, the purpose and the bytes that did not fit; what was written of the extent is
    /// released.
    StatusOr<SpillExtent> Write(const void* data, size_t size);
    /// Reads `extent` back into `out` (extent.raw_bytes bytes). A chunk whose checksum or size does
    /// not match what was written is DataLoss naming the directory, the offset and both checksums.
    Status Read(const SpillExtent& extent, void* out) const;
    /// Gives the extent's space back; it cannot be read afterwards.
    void Release(const SpillExtent& extent);

    const std::filesystem::path& dir() const { return dir_; }
    const std::string& purpose() const { return purpose_; }
    SpillStats stats() const;

  private:
    SpillFile(std::filesystem::path dir, std::string purpose, int fd)
        : dir_(std::move(dir)), purpose_(std::move(purpose)), fd_(fd) {}
    /// Writes `size` bytes at a new offset; returns the offset.
    StatusOr<uint64_t> Append(const void* data, size_t size);

    const std::filesystem::path dir_;
    const std::string purpose_;
    const int fd_;
    mutable std::mutex mutex_;  // guards end_ and stats_
    uint64_t end_ = 0;
    mutable SpillStats stats_;
};

}  // namespace nave::store
