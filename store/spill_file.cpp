#include "store/spill_file.h"

#include <fcntl.h>
#include <lz4.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "src/core/hash.h"
#include "src/core/memory.h"

namespace nave::store {
namespace {

std::string ErrnoText(int err) { return std::strerror(err); }

/// Opens a file without a name in `dir`: O_TMPFILE where the file system has it, else a named file
/// unlinked at once. Returns the descriptor or -errno.
int OpenNameless(const std::filesystem::path& dir) {
    int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd >= 0) return fd;
    if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) return -errno;
    std::string pattern = (dir / "nave-spill-XXXXXX").string();
    fd = ::mkostemp(pattern.data(), O_CLOEXEC);
    if (fd < 0) return -errno;
    ::unlink(pattern.c_str());
    return fd;
}

}  // namespace

StatusOr<std::unique_ptr<SpillFile>> SpillFile::Create(const std::filesystem::path& dir,
                                                       std::string purpose) {
    const std::filesystem::path where = dir.empty() ? std::filesystem::path(".") : dir;
    const int fd = OpenNameless(where);
    if (fd < 0) {
        return IoError("cannot create a spill file for {} in {}: {}", purpose, where.string(),
                       ErrnoText(-fd));
    }
    return std::unique_ptr<SpillFile>(new SpillFile(where, std::move(purpose), fd));
}

SpillFile::~SpillFile() { ::close(fd_); }

StatusOr<uint64_t> SpillFile::Append(const void* data, size_t size) {
    uint64_t offset = 0;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        offset = end_;
        end_ += size;
    }
    const char* p = static_cast<const char*>(data);
    size_t done = 0;
    while (done < size) {
        const ssize_t n = ::pwrite(fd_, p + done, size - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int err = n < 0 ? errno : ENOSPC;
            return IoError("cannot spill {} of {} to {}: {}", FormatBytes(size), purpose_,
                           dir_.string(), ErrnoText(err));
        }
        done += size_t(n);
    }
    return offset;
}

StatusOr<SpillExtent> SpillFile::Write(const void* data, size_t size) {
    SpillExtent extent;
    extent.raw_bytes = size;
    const char* src = static_cast<const char*>(data);
    std::vector<char> packed(size_t(LZ4_compressBound(int(std::min(size, kChunkBytes)))));
    for (size_t at = 0; at < size; at += kChunkBytes) {
        const int raw = int(std::min(kChunkBytes, size - at));
        const int n = LZ4_compress_default(src + at, packed.data(), raw, int(packed.size()));
        // Data LZ4 cannot shrink is stored as it is (stored == raw marks it).
        const bool compressed = n > 0 && n < raw;
        const char* bytes = compressed ? packed.data() : src + at;
        SpillChunk chunk;
        chunk.raw = uint32_t(raw);
        chunk.stored = compressed ? uint32_t(n) : uint32_t(raw);
        chunk.checksum = Checksum64(bytes, chunk.stored);
        StatusOr<uint64_t> offset = Append(bytes, chunk.stored);
        if (!offset.ok()) {
            Release(extent);
            return offset.status();
        }
        chunk.offset = *offset;
        extent.stored_bytes += chunk.stored;
        extent.chunks.push_back(chunk);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.raw_bytes_written += extent.raw_bytes;
    stats_.stored_bytes_written += extent.stored_bytes;
    stats_.stored_bytes += extent.stored_bytes;
    stats_.peak_stored_bytes = std::max(stats_.peak_stored_bytes, stats_.stored_bytes);
    return extent;
}

Status SpillFile::Read(const SpillExtent& extent, void* out) const {
    char* dst = static_cast<char*>(out);
    std::vector<char> packed;
    uint64_t at = 0;
    for (const SpillChunk& chunk : extent.chunks) {
        const bool compressed = chunk.stored != chunk.raw;
        char* bytes = dst + at;
        if (compressed) {
            packed.resize(chunk.stored);
            bytes = packed.data();
        }
        size_t done = 0;
        while (done < chunk.stored) {
            const ssize_t n =
                ::pread(fd_, bytes + done, chunk.stored - done, off_t(chunk.offset + done));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                return IoError("cannot read back {} of {} spilled to {} at offset {}: {}",
                               FormatBytes(chunk.stored), purpose_, dir_.string(), chunk.offset,
                               n < 0 ? ErrnoText(errno) : std::string("end of file"));
            }
            done += size_t(n);
        }
        const uint64_t sum = Checksum64(bytes, chunk.stored);
        if (sum != chunk.checksum) {
            return DataLossError(
                "{} spilled to {}: chunk at offset {} ({} bytes) has checksum {}, written as {}",
                purpose_, dir_.string(), chunk.offset, chunk.stored, ChecksumHex(sum),
                ChecksumHex(chunk.checksum));
        }
        if (compressed) {
            const int n = LZ4_decompress_safe(bytes, dst + at, int(chunk.stored), int(chunk.raw));
            if (n != int(chunk.raw)) {
                return DataLossError(
                    "{} spilled to {}: chunk at offset {} decompresses to {} bytes, expected {}",
                    purpose_, dir_.string(), chunk.offset, n, chunk.raw);
            }
        }
        at += chunk.raw;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.raw_bytes_read += extent.raw_bytes;
    return Status::Ok();
}

void SpillFile::Release(const SpillExtent& extent) {
    for (const SpillChunk& chunk : extent.chunks) {
        // Best effort: a file system without hole punching keeps the space until the file closes.
        (void)::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, off_t(chunk.offset),
                          off_t(chunk.stored));
    }
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.stored_bytes -= std::min(stats_.stored_bytes, extent.stored_bytes);
}

SpillStats SpillFile::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
}

}  // namespace nave::store
