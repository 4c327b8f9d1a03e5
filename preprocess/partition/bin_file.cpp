#include "preprocess/partition/bin_file.h"

#include <lz4.h>

#include <cerrno>
#include <cstring>

namespace nave::preprocess {
namespace {

constexpr uint32_t kHasNormals = 1u << 30, kHasUvs = 1u << 31, kMaterialMask = (1u << 30) - 1;

template <typename T>
void Put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

}  // namespace

size_t BinRecordBytes(const Triangle& t) {
    return 40 + (t.has_normals ? 36 : 0) + (t.has_uvs ? 24 : 0);
}

StatusOr<std::unique_ptr<BinWriter>> BinWriter::Create(const std::filesystem::path& path,
                                                       size_t block_bytes) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr)
        return IoError("{}: cannot create temporary bin: {}", path.string(), std::strerror(errno));
    return std::unique_ptr<BinWriter>(new BinWriter(path, f, block_bytes));
}

BinWriter::BinWriter(std::filesystem::path path, std::FILE* file, size_t block_bytes)
    : path_(std::move(path)), file_(file), block_bytes_(block_bytes) {}

BinWriter::~BinWriter() {
    if (file_ != nullptr) std::fclose(file_);
}

Status BinWriter::Append(const Triangle& t) {
    if (raw_.capacity() < block_bytes_ + 128) raw_.reserve(block_bytes_ + 128);
    Put(raw_, t.p);
    uint32_t tag = (t.material & kMaterialMask) | (t.has_normals ? kHasNormals : 0) |
                   (t.has_uvs ? kHasUvs : 0);
    Put(raw_, tag);
    if (t.has_normals) Put(raw_, t.n);
    if (t.has_uvs) Put(raw_, t.uv);
    ++triangles_;
    if (raw_.size() >= block_bytes_) return FlushBlock();
    return Status::Ok();
}

Status BinWriter::FlushBlock() {
    if (raw_.empty()) return Status::Ok();
    int bound = LZ4_compressBound(int(raw_.size()));
    if (compressed_.size() < size_t(bound)) compressed_.resize(bound);
    int n = LZ4_compress_default(raw_.data(), compressed_.data(), int(raw_.size()), bound);
    if (n <= 0)
        return InternalError("{}: LZ4 compression failed ({}) on a {}-byte block", path_.string(),
                             n, raw_.size());
    uint32_t header[2] = {uint32_t(raw_.size()), uint32_t(n)};
    if (std::fwrite(header, sizeof(header), 1, file_) != 1 ||
        std::fwrite(compressed_.data(), n, 1, file_) != 1) {
        return IoError("{}: write failed at byte {}: {} (disk full?)", path_.string(), file_bytes_,
                       std::strerror(errno));
    }
    file_bytes_ += sizeof(header) + n;
    raw_.clear();
    return Status::Ok();
}

Status BinWriter::Close() {
    NAVE_RETURN_IF_ERROR(FlushBlock());
    if (file_ != nullptr) {
        int rc = std::fclose(file_);
        file_ = nullptr;
        if (rc != 0) return IoError("{}: close failed: {}", path_.string(), std::strerror(errno));
    }
    std::string().swap(raw_);
    std::vector<char>().swap(compressed_);
    return Status::Ok();
}

StatusOr<std::unique_ptr<BinReader>> BinReader::Open(const std::filesystem::path& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (f == nullptr)
        return IoError("{}: cannot open temporary bin: {}", path.string(), std::strerror(errno));
    return std::unique_ptr<BinReader>(new BinReader(path, f));
}

BinReader::~BinReader() {
    if (file_ != nullptr) std::fclose(file_);
}

Status BinReader::NextBlock() {
    uint32_t header[2];
    size_t got = std::fread(header, 1, sizeof(header), file_);
    if (got == 0) {
        raw_.clear();
        pos_ = 0;
        return Status::Ok();
    }
    if (got != sizeof(header) || header[0] > (1u << 30) ||
        header[1] > uint32_t(LZ4_compressBound(int(header[0])))) {
        return DataLossError("{} @{}: corrupt bin block header", path_.string(), offset_);
    }
    compressed_.resize(header[1]);
    raw_.resize(header[0]);
    if (std::fread(compressed_.data(), 1, header[1], file_) != header[1]) {
        return DataLossError("{} @{}: truncated bin block", path_.string(), offset_);
    }
    int n = LZ4_decompress_safe(compressed_.data(), raw_.data(), int(header[1]), int(header[0]));
    if (n != int(header[0])) {
        return DataLossError("{} @{}: LZ4 block decodes to {} bytes, expected {}", path_.string(),
                             offset_, n, header[0]);
    }
    offset_ += sizeof(header) + header[1];
    pos_ = 0;
    return Status::Ok();
}

StatusOr<bool> BinReader::Read(std::vector<Triangle>& out, size_t max) {
    size_t added = 0;
    while (added < max) {
        if (pos_ >= raw_.size()) {
            NAVE_RETURN_IF_ERROR(NextBlock());
            if (raw_.empty()) break;
        }
        Triangle t;
        const char* p = raw_.data() + pos_;
        std::memcpy(&t.p, p, sizeof(t.p));
        uint32_t tag;
        std::memcpy(&tag, p + 36, 4);
        pos_ += 40;
        t.material = tag & kMaterialMask;
        t.has_normals = (tag & kHasNormals) != 0;
        t.has_uvs = (tag & kHasUvs) != 0;
        if (t.has_normals) {
            std::memcpy(&t.n, raw_.data() + pos_, sizeof(t.n));
            pos_ += sizeof(t.n);
        }
        if (t.has_uvs) {
            std::memcpy(&t.uv, raw_.data() + pos_, sizeof(t.uv));
            pos_ += sizeof(t.uv);
        }
        if (pos_ > raw_.size())
            return DataLossError("{} @{}: record runs past its block", path_.string(), offset_);
        out.push_back(t);
        ++added;
    }
    return added > 0;
}

}  // namespace nave::preprocess
