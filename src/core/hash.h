#pragma once
// Checksums for everything nave stores on disk: XXH64 (xxHash, seed 0), 64 bits.

#include <cstddef>
#include <cstdint>
#include <string>

namespace nave {

/// XXH64 of `size` bytes, seed 0.
uint64_t Checksum64(const void* data, size_t size);
/// 16 lower-case hex digits, as checksums are printed in messages.
std::string ChecksumHex(uint64_t checksum);

}  // namespace nave
