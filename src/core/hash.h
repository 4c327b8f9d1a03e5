#pragma once
// Checksums for everything nave stores on disk: XXH64 (xxHash, seed 0), 64 bits.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace nave {

/// XXH64 of `size` bytes, seed 0.
uint64_t Checksum64(const void* data, size_t size);
/// XXH64 (seed 0) of bytes given in pieces: equal to Checksum64 of their concatenation, without
/// holding it. Not thread-safe.
class StreamingChecksum64 {
  public:
    StreamingChecksum64();
    ~StreamingChecksum64();
    StreamingChecksum64(const StreamingChecksum64&) = delete;
    StreamingChecksum64& operator=(const StreamingChecksum64&) = delete;
    void Update(const void* data, size_t size);
    /// The checksum of everything given so far.
    uint64_t Digest() const;

  private:
    struct State;
    std::unique_ptr<State> state_;
};

/// 16 lower-case hex digits, as checksums are printed in messages.
std::string ChecksumHex(uint64_t checksum);

}  // namespace nave
