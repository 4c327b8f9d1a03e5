#include "preprocess/import/stream_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace nave::preprocess {
namespace {

constexpr size_t kChunkBytes = 1 << 20;
constexpr size_t kMaxLineBytes = 64u << 20;

}  // namespace

StatusOr<StreamReader> StreamReader::Open(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return NotFoundError("{}: no such file", path.string());
    if (std::filesystem::is_directory(path, ec)) {
        return InvalidArgumentError("{}: is a directory, expected a model file", path.string());
    }
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (file == nullptr) return IoError("{}: cannot open: {}", path.string(), std::strerror(errno));
    uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) size = 0;
    return StreamReader(path, file, size);
}

StreamReader::StreamReader(std::filesystem::path path, std::FILE* file, uint64_t size)
    : path_(std::move(path)), file_(file), file_size_(size) {
    // A small file gets a buffer its size (plus the byte that finds the end), not a whole chunk:
    // the buffer doubles anyway if a line or the file turns out longer.
    buffer_.resize(size_t(std::clamp<uint64_t>(size + 1, 4096, kChunkBytes)));
}

StreamReader::StreamReader(StreamReader&& other) noexcept { *this = std::move(other); }

StreamReader& StreamReader::operator=(StreamReader&& other) noexcept {
    if (this != &other) {
        if (file_ != nullptr) std::fclose(file_);
        path_ = std::move(other.path_);
        file_ = std::exchange(other.file_, nullptr);
        file_size_ = other.file_size_;
        buffer_ = std::move(other.buffer_);
        begin_ = other.begin_;
        end_ = other.end_;
        eof_ = other.eof_;
        consumed_offset_ = other.consumed_offset_;
        line_number_ = other.line_number_;
    }
    return *this;
}

StreamReader::~StreamReader() {
    if (file_ != nullptr) std::fclose(file_);
}

Status StreamReader::Fill() {
    if (begin_ > 0) {
        std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
        end_ -= begin_;
        begin_ = 0;
    }
    if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
    size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
    if (got == 0) {
        if (std::ferror(file_))
            return IoError("{}: read error at byte {}", path_.string(), consumed_offset_);
        eof_ = true;
    }
    end_ += got;
    return Status::Ok();
}

StatusOr<bool> StreamReader::NextLine(std::string_view& line) {
    size_t scan_from = begin_;
    while (true) {
        const char* start = buffer_.data() + scan_from;
        const void* nl = std::memchr(start, '\n', end_ - scan_from);
        if (nl != nullptr) {
            size_t nl_pos = static_cast<const char*>(nl) - buffer_.data();
            size_t len = nl_pos - begin_;
            line = std::string_view(buffer_.data() + begin_, len);
            if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
            consumed_offset_ += len + 1;
            begin_ = nl_pos + 1;
            ++line_number_;
            return true;
        }
        if (eof_) {
            if (begin_ == end_) return false;
            line = std::string_view(buffer_.data() + begin_, end_ - begin_);
            if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
            consumed_offset_ += end_ - begin_;
            begin_ = end_;
            ++line_number_;
            return true;
        }
        if (end_ - begin_ > kMaxLineBytes) {
            return DataLossError("{}:{}: line longer than {} bytes: expected a text file",
                                 path_.string(), line_number_ + 1, kMaxLineBytes);
        }
        size_t scanned = end_ - begin_;
        NAVE_RETURN_IF_ERROR(Fill());
        scan_from = begin_ + scanned;
    }
}

StatusOr<size_t> StreamReader::ReadSome(void* out, size_t size) {
    char* dst = static_cast<char*>(out);
    size_t done = 0;
    while (done < size) {
        if (begin_ == end_) {
            if (eof_) break;
            NAVE_RETURN_IF_ERROR(Fill());
            continue;
        }
        size_t n = std::min(size - done, end_ - begin_);
        std::memcpy(dst + done, buffer_.data() + begin_, n);
        begin_ += n;
        done += n;
        consumed_offset_ += n;
    }
    return done;
}

Status StreamReader::ReadBytes(void* out, size_t size) {
    uint64_t at = consumed_offset_;
    NAVE_ASSIGN_OR_RETURN(size_t got, ReadSome(out, size));
    if (got != size) {
        return DataLossError("{} @{}: truncated: expected {} more bytes, found {} (file size {})",
                             path_.filename().string(), at, size, got, file_size_);
    }
    return Status::Ok();
}

std::string StreamReader::Where() const {
    return fmt::format("{}:{}", path_.filename().string(), line_number_);
}

std::string StreamReader::WhereOffset() const {
    return fmt::format("{} @{}", path_.filename().string(), consumed_offset_);
}

}  // namespace nave::preprocess
