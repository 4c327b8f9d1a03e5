#include "src/core/file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

namespace nave {
namespace {

std::atomic<uint64_t> g_temp_counter{0};

std::string ErrnoText() { return std::strerror(errno); }

/// Opens `path` read-only with `flags` and fsyncs it: files another writer wrote, and directories
/// after a rename.
Status SyncPath(const std::filesystem::path& path, int flags, const char* what) {
    int fd = ::open(path.empty() ? "." : path.c_str(), O_RDONLY | O_CLOEXEC | flags);
    if (fd < 0) return IoError("cannot open {}{} to sync it: {}", what, path.string(), ErrnoText());
    int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0) return IoError("cannot sync {}{}: {}", what, path.string(), ErrnoText());
    return Status::Ok();
}

Status FsyncDirectory(const std::filesystem::path& dir) {
    return SyncPath(dir, O_DIRECTORY, "directory ");
}

}  // namespace

Status SyncFile(const std::filesystem::path& path) { return SyncPath(path, 0, ""); }

StatusOr<AtomicFile> AtomicFile::Create(const std::filesystem::path& path) {
    std::filesystem::path temp = path;
    temp += fmt::format(".tmp-{}-{}", ::getpid(), g_temp_counter.fetch_add(1));
    int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) {
        return IoError("cannot create {} (temporary file for {}): {}", temp.string(), path.string(),
                       ErrnoText());
    }
    return AtomicFile(path, temp, fd);
}

AtomicFile::AtomicFile(AtomicFile&& o) noexcept
    : path_(std::move(o.path_)), temp_path_(std::move(o.temp_path_)), fd_(o.fd_), size_(o.size_) {
    o.fd_ = -1;
    o.temp_path_.clear();
}

AtomicFile& AtomicFile::operator=(AtomicFile&& o) noexcept {
    if (this != &o) {
        Abandon();
        path_ = std::move(o.path_);
        temp_path_ = std::move(o.temp_path_);
        fd_ = o.fd_;
        size_ = o.size_;
        o.fd_ = -1;
        o.temp_path_.clear();
    }
    return *this;
}

AtomicFile::~AtomicFile() { Abandon(); }

void AtomicFile::Abandon() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
    temp_path_.clear();
}

Status AtomicFile::Write(const void* data, size_t size) {
    NAVE_RETURN_IF_ERROR(WriteAt(size_, data, size));
    return Status::Ok();
}

Status AtomicFile::WriteAt(uint64_t offset, const void* data, size_t size) {
    NAVE_CHECK(fd_ >= 0) << "write to a closed AtomicFile " << path_;
    const char* p = static_cast<const char*>(data);
    uint64_t at = offset;
    size_t left = size;
    while (left > 0) {
        ssize_t n = ::pwrite(fd_, p, left, static_cast<off_t>(at));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            return IoError("cannot write {} bytes to {} (temporary file for {}) at offset {}: {}",
                           left, temp_path_.string(), path_.string(), at,
                           n < 0 ? ErrnoText() : "no space written (disk full?)");
        }
        p += n;
        at += uint64_t(n);
        left -= size_t(n);
    }
    size_ = std::max(size_, offset + size);
    return Status::Ok();
}

Status AtomicFile::Sync() {
    NAVE_CHECK(fd_ >= 0) << "sync of a closed AtomicFile " << path_;
    if (::fsync(fd_) != 0) return IoError("cannot sync {}: {}", temp_path_.string(), ErrnoText());
    return Status::Ok();
}

Status AtomicFile::Commit() {
    NAVE_CHECK(fd_ >= 0) << "commit of a closed AtomicFile " << path_;
    NAVE_RETURN_IF_ERROR(Sync());
    if (::close(fd_) != 0) {
        fd_ = -1;
        return IoError("cannot close {}: {}", temp_path_.string(), ErrnoText());
    }
    fd_ = -1;
    if (::rename(temp_path_.c_str(), path_.c_str()) != 0) {
        return IoError("cannot rename {} to {}: {}", temp_path_.string(), path_.string(),
                       ErrnoText());
    }
    temp_path_.clear();
    return FsyncDirectory(path_.parent_path());
}

StatusOr<ReadOnlyFile> ReadOnlyFile::Open(const std::filesystem::path& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        if (errno == ENOENT) return NotFoundError("{}: no such file", path.string());
        return IoError("cannot open {}: {}", path.string(), ErrnoText());
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        return IoError("{} is not a regular file", path.string());
    }
    return ReadOnlyFile(path, fd, uint64_t(st.st_size));
}

ReadOnlyFile::ReadOnlyFile(ReadOnlyFile&& o) noexcept
    : path_(std::move(o.path_)), fd_(o.fd_), size_(o.size_) {
    o.fd_ = -1;
}

ReadOnlyFile& ReadOnlyFile::operator=(ReadOnlyFile&& o) noexcept {
    if (this != &o) {
        if (fd_ >= 0) ::close(fd_);
        path_ = std::move(o.path_);
        fd_ = o.fd_;
        size_ = o.size_;
        o.fd_ = -1;
    }
    return *this;
}

ReadOnlyFile::~ReadOnlyFile() {
    if (fd_ >= 0) ::close(fd_);
}

Status ReadOnlyFile::ReadAt(uint64_t offset, void* out, size_t size) const {
    if (offset > size_ || size > size_ - offset) {
        return DataLossError(
            "{}: truncated: need {} bytes at offset {} (0x{:x}) but the file has {} bytes",
            path_.string(), size, offset, offset, size_);
    }
    char* p = static_cast<char*>(out);
    uint64_t at = offset;
    size_t left = size;
    while (left > 0) {
        ssize_t n = ::pread(fd_, p, left, static_cast<off_t>(at));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0)
            return IoError("{}: read of {} bytes at offset {} failed: {}", path_.string(), left, at,
                           ErrnoText());
        if (n == 0)
            return DataLossError("{}: truncated at offset {} (0x{:x})", path_.string(), at, at);
        p += n;
        at += uint64_t(n);
        left -= size_t(n);
    }
    return Status::Ok();
}

StatusOr<std::string> ReadFileToString(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(ReadOnlyFile file, ReadOnlyFile::Open(path));
    std::string data(file.size(), '\0');
    NAVE_RETURN_IF_ERROR(file.ReadAt(0, data.data(), data.size()));
    return data;
}

}  // namespace nave
