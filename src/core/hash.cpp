#include "core/hash.h"

#include <xxhash.h>

#include <fmt/format.h>

namespace nave {

uint64_t Checksum64(const void* data, size_t size) { return XXH64(data, size, 0); }

std::string ChecksumHex(uint64_t checksum) { return fmt::format("{:016x}", checksum); }

}  // namespace nave
