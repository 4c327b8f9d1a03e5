#pragma once
// Little-endian byte strings of plain values and arrays, for state that nave saves and reads back
// whole (render checkpoints). The reader never reads past its end: a short string is a DataLoss
// status naming what was being read, at which offset, and how many bytes it needed.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "src/core/status.h"

namespace nave {

static_assert(std::endian::native == std::endian::little,
              "byte streams are little-endian; add byte swaps");

/// `bytes` read back as records of T laid end to end (as std::as_bytes of a span of T lays them:
/// records that other processes of a distributed render sent). `what` names them in the error.
/// Errors: Internal for bytes that are not whole records.
template <typename T>
StatusOr<std::vector<T>> RecordsFromBytes(std::span<const std::byte> bytes, std::string_view what) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (bytes.size() % sizeof(T) != 0) {
        return InternalError("{}: {} bytes, not whole records of {}", what, bytes.size(),
                             sizeof(T));
    }
    std::vector<T> records(bytes.size() / sizeof(T));
    if (!bytes.empty()) std::memcpy(records.data(), bytes.data(), bytes.size());
    return records;
}

/// Appends values to a byte string. Not thread-safe.
class ByteWriter {
  public:
    template <typename T>
    void Put(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
    }
    /// `count` values of T from `values`, preceded by the count (uint64).
    template <typename T>
    void PutArray(const T* values, uint64_t count) {
        static_assert(std::is_trivially_copyable_v<T>);
        Put(count);
        bytes_.append(reinterpret_cast<const char*>(values), size_t(count) * sizeof(T));
    }
    void PutString(std::string_view text) { PutArray(text.data(), text.size()); }
    /// Makes room for `bytes` more bytes at once (large states put value by value).
    void Reserve(size_t bytes) { bytes_.reserve(bytes_.size() + bytes); }

    const std::string& bytes() const { return bytes_; }
    std::string Take() { return std::move(bytes_); }

  private:
    std::string bytes_;
};

/// Reads values back in the order a ByteWriter put them. `what` names the bytes in messages
/// ("checkpoint r.ckpt section film"). Not thread-safe.
class ByteReader {
  public:
    ByteReader(std::string_view bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

    template <typename T>
    Status Get(T* value, std::string_view field) {
        static_assert(std::is_trivially_copyable_v<T>);
        NAVE_RETURN_IF_ERROR(Need(sizeof(T), field));
        std::memcpy(value, bytes_.data() + offset_, sizeof(T));
        offset_ += sizeof(T);
        return Status::Ok();
    }
    /// The count PutArray wrote before its values, which must be `expected`; the values can then
    /// be read one by one with Get.
    Status GetCount(uint64_t expected, std::string_view field) {
        uint64_t count = 0;
        NAVE_RETURN_IF_ERROR(Get(&count, field));
        if (count == expected) return Status::Ok();
        return DataLossError("{} @{}: {} holds {} values, expected {}", what_, offset_ - 8, field,
                             count, expected);
    }
    /// An array written by PutArray, which must hold exactly `expected` values.
    template <typename T>
    Status GetArray(T* values, uint64_t expected, std::string_view field) {
        NAVE_RETURN_IF_ERROR(GetCount(expected, field));
        NAVE_RETURN_IF_ERROR(Need(expected * sizeof(T), field));
        std::memcpy(values, bytes_.data() + offset_, size_t(expected) * sizeof(T));
        offset_ += size_t(expected) * sizeof(T);
        return Status::Ok();
    }
    /// A string written by PutString, of at most `max_bytes`.
    Status GetString(std::string* text, uint64_t max_bytes, std::string_view field) {
        uint64_t count = 0;
        NAVE_RETURN_IF_ERROR(Get(&count, field));
        if (count > max_bytes) {
            return DataLossError("{} @{}: {} is {} bytes long, at most {} expected", what_,
                                 offset_ - 8, field, count, max_bytes);
        }
        NAVE_RETURN_IF_ERROR(Need(count, field));
        text->assign(bytes_.data() + offset_, size_t(count));
        offset_ += size_t(count);
        return Status::Ok();
    }
    /// Ok when every byte was read: extra bytes mean a writer that does not match this reader.
    Status ExpectEnd() const {
        if (offset_ == bytes_.size()) return Status::Ok();
        return DataLossError("{}: {} bytes left over after the last field at @{}", what_,
                             bytes_.size() - offset_, offset_);
    }
    uint64_t offset() const { return offset_; }
    const std::string& what() const { return what_; }

  private:
    Status Need(uint64_t n, std::string_view field) const {
        if (n <= bytes_.size() - offset_) return Status::Ok();
        return DataLossError("{} @{}: {} needs {} bytes, only {} left (truncated)", what_, offset_,
                             field, n, bytes_.size() - offset_);
    }
    std::string_view bytes_;
    std::string what_;
    size_t offset_ = 0;
};

}  // namespace nave
