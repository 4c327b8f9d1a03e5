#include "src/core/hash.h"

#include <fmt/format.h>
#include <xxhash.h>

#include "src/core/check.h"

namespace nave {

uint64_t Checksum64(const void* data, size_t size) { return XXH64(data, size, 0); }

// xxhash's state is opaque unless linked statically: it lives on its heap.
struct StreamingChecksum64::State {
    State() : xxh(XXH64_createState()) {
        NAVE_CHECK(xxh != nullptr) << "XXH64_createState";
        XXH64_reset(xxh, 0);
    }
    ~State() { XXH64_freeState(xxh); }
    XXH64_state_t* xxh;
};

StreamingChecksum64::StreamingChecksum64() : state_(std::make_unique<State>()) {}

StreamingChecksum64::~StreamingChecksum64() = default;

void StreamingChecksum64::Update(const void* data, size_t size) {
    XXH64_update(state_->xxh, data, size);
}

uint64_t StreamingChecksum64::Digest() const { return XXH64_digest(state_->xxh); }

std::string ChecksumHex(uint64_t checksum) { return fmt::format("{:016x}", checksum); }

}  // namespace nave
