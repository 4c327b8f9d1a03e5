#include "src/render/stream/ray_message.h"

#include <lz4.h>

#include <bit>
#include <cstddef>
#include <cstring>
#include <type_traits>

namespace nave::render {

static_assert(std::is_trivially_copyable_v<RayRecord>, "rays travel as their bytes");

namespace {

void PutU32(std::byte* at, uint32_t v) { std::memcpy(at, &v, 4); }

uint32_t GetU32(const std::byte* at) {
    uint32_t v;
    std::memcpy(&v, at, 4);
    return v;
}

/// Where a record's wavelengths and their pdfs lie (SampledWavelengths: four wavelengths, then four
/// pdfs).
constexpr size_t kLambdaAt = offsetof(RayRecord, lambda);
constexpr size_t kPdfAt = kLambdaAt + kNumWavelengths * sizeof(float);
static_assert(sizeof(SampledWavelengths) == 2 * kNumWavelengths * sizeof(float));

/// XORs each pdf of record `r` with the pdf SampledWavelengths::SampleVisible gives its wavelength,
/// which it almost always is: the pdfs, as random as the wavelengths, become zeros that LZ4 packs
/// to nothing, and the same XOR brings them back (every rank runs the same nave).
void XorPredictedPdfs(std::byte* r) {
    for (int i = 0; i < kNumWavelengths; ++i) {
        float lambda;
        std::memcpy(&lambda, r + kLambdaAt + 4 * i, 4);
        const uint32_t predicted = std::bit_cast<uint32_t>(VisibleWavelengthsPdf(lambda));
        PutU32(r + kPdfAt + 4 * i, GetU32(r + kPdfAt + 4 * i) ^ predicted);
    }
}

/// XORs the secondary wavelengths of record `r` with those SampledWavelengths::SampleVisible draws
/// with the first: SampleVisible rotates one number u by quarters, so the first wavelength gives u
/// back (VisibleWavelengthsCdf) and u the others, to a few ulps: their random-looking high bytes
/// become zeros, and the same XOR, the first wavelength unchanged, brings them back.
void XorPredictedSecondaries(std::byte* r) {
    float first;
    std::memcpy(&first, r + kLambdaAt, 4);
    const float u = VisibleWavelengthsCdf(first);
    for (int i = 1; i < kNumWavelengths; ++i) {
        // As SampleVisible rotates u.
        float up = u + float(i) / kNumWavelengths;
        if (up >= 1.f) up -= 1.f;
        const uint32_t predicted = std::bit_cast<uint32_t>(SampleVisibleWavelengths(up));
        PutU32(r + kLambdaAt + 4 * i, GetU32(r + kLambdaAt + 4 * i) ^ predicted);
    }
}

/// Transforms each group's records of message `m` in place for LZ4 (`pack`), or back: the pdfs
/// XORed with their prediction (XorPredictedPdfs), then the secondary wavelengths with theirs
/// (XorPredictedSecondaries), then the bytes transposed (the bytes at one
/// offset of every record side by side: kinds, depths, pixel rows, exponents), through `scratch`.
/// Stops at the first group that does not fit: the raw message's checks (ForEachRayGroup) name it.
void TransformGroups(std::span<std::byte> m, bool pack, std::vector<std::byte>* scratch) {
    constexpr size_t kRecord = sizeof(RayRecord);
    if (m.size() < kRayMessageHeaderBytes) return;
    const uint32_t groups = GetU32(m.data() + 4);
    size_t at = kRayMessageHeaderBytes;
    for (uint32_t g = 0; g < groups && m.size() - at >= kRayGroupHeaderBytes; ++g) {
        const uint64_t n = GetU32(m.data() + at + 4);
        at += kRayGroupHeaderBytes;
        if (m.size() - at < n * kRecord) return;
        std::byte* block = m.data() + at;
        scratch->assign(block, block + n * kRecord);
        std::byte* copy = scratch->data();
        if (pack) {
            for (uint64_t i = 0; i < n; ++i) {
                // The pdfs' prediction reads the wavelengths: before those are changed.
                XorPredictedPdfs(copy + i * kRecord);
                XorPredictedSecondaries(copy + i * kRecord);
            }
            for (uint64_t i = 0; i < n; ++i)
                for (size_t k = 0; k < kRecord; ++k) block[k * n + i] = copy[i * kRecord + k];
        } else {
            for (uint64_t i = 0; i < n; ++i)
                for (size_t k = 0; k < kRecord; ++k) block[i * kRecord + k] = copy[k * n + i];
            for (uint64_t i = 0; i < n; ++i) {
                XorPredictedSecondaries(block + i * kRecord);
                XorPredictedPdfs(block + i * kRecord);
            }
        }
        at += n * kRecord;
    }
}

}  // namespace

std::vector<std::byte> PackRayMessage(std::span<const std::byte> raw) {
    std::vector<std::byte> shuffled(raw.begin(), raw.end()), scratch;
    TransformGroups(shuffled, /*pack=*/true, &scratch);
    NAVE_CHECK_LE(raw.size(), size_t(LZ4_MAX_INPUT_SIZE)) << "a ray message too large for LZ4";
    std::vector<std::byte> packed(8 + size_t(LZ4_compressBound(int(raw.size()))));
    PutU32(packed.data(), kPackedRayMessageVersion);
    PutU32(packed.data() + 4, uint32_t(raw.size()));
    const int n = LZ4_compress_default(reinterpret_cast<const char*>(shuffled.data()),
                                       reinterpret_cast<char*>(packed.data() + 8), int(raw.size()),
                                       int(packed.size() - 8));
    NAVE_CHECK_GT(n, 0) << "LZ4 failed on a ray message of " << raw.size() << " bytes";
    packed.resize(8 + size_t(n));
    return packed;
}

bool IsPackedRayMessage(std::span<const std::byte> message) {
    return message.size() >= 8 && GetU32(message.data()) == kPackedRayMessageVersion;
}

Status UnpackRayMessage(std::span<const std::byte> packed, size_t max_raw_bytes,
                        std::string_view what, std::vector<std::byte>* raw) {
    if (!IsPackedRayMessage(packed))
        return DataLossError("{}: not a packed ray message ({} bytes)", what, packed.size());
    const uint32_t size = GetU32(packed.data() + 4);
    if (size > max_raw_bytes || size > uint32_t(LZ4_MAX_INPUT_SIZE))
        return DataLossError("{}: a packed message of {} bytes unpacks to {} (at most {})", what,
                             packed.size(), size, max_raw_bytes);
    raw->resize(size);
    const int n = LZ4_decompress_safe(reinterpret_cast<const char*>(packed.data() + 8),
                                      reinterpret_cast<char*>(raw->data()), int(packed.size() - 8),
                                      int(size));
    if (n != int(size))
        return DataLossError("{}: its LZ4 block of {} bytes does not unpack to the {} it announces",
                             what, packed.size() - 8, size);
    std::vector<std::byte> scratch;
    TransformGroups(*raw, /*pack=*/false, &scratch);
    return Status::Ok();
}

RayMessage::RayMessage() { bytes_.resize(kRayMessageHeaderBytes); }

void RayMessage::Append(uint32_t slot, std::span<const RayRecord> rays) {
    if (rays.empty()) return;
    const size_t at = bytes_.size();
    bytes_.resize(at + kRayGroupHeaderBytes + rays.size_bytes());
    PutU32(bytes_.data() + at, slot);
    PutU32(bytes_.data() + at + 4, uint32_t(rays.size()));
    std::memcpy(bytes_.data() + at + kRayGroupHeaderBytes, rays.data(), rays.size_bytes());
    ++groups_;
    rays_ += rays.size();
}

std::vector<std::byte> RayMessage::Take() {
    PutU32(bytes_.data(), kRayMessageVersion);
    PutU32(bytes_.data() + 4, groups_);
    std::vector<std::byte> out = std::move(bytes_);
    bytes_.assign(kRayMessageHeaderBytes, std::byte{0});
    groups_ = 0;
    rays_ = 0;
    return out;
}

StatusOr<uint64_t> ForEachRayGroup(
    std::span<const std::byte> message, uint32_t slot_count, std::string_view what,
    const std::function<void(uint32_t slot, std::span<const RayRecord> rays)>& visit) {
    if (message.size() < kRayMessageHeaderBytes) {
        return DataLossError("{}: a message of {} bytes (expected at least its {}-byte header)",
                             what, message.size(), kRayMessageHeaderBytes);
    }
    const uint32_t version = GetU32(message.data());
    if (version != kRayMessageVersion) {
        return DataLossError(
            "{}: message version {} (expected {}: every rank must run the same nave)", what,
            version, kRayMessageVersion);
    }
    const uint32_t groups = GetU32(message.data() + 4);
    // Check the whole message before visiting any of it: a damaged message delivers nothing.
    size_t at = kRayMessageHeaderBytes;
    for (uint32_t g = 0; g < groups; ++g) {
        if (message.size() - at < kRayGroupHeaderBytes) {
            return DataLossError(
                "{}: group {} of {} at byte {}: the message ends at {} (cut short)", what, g,
                groups, at, message.size());
        }
        const uint32_t slot = GetU32(message.data() + at);
        const uint64_t count = GetU32(message.data() + at + 4);
        if (slot >= slot_count) {
            return DataLossError("{}: group {} at byte {} names brick slot {} (expected < {})",
                                 what, g, at, slot, slot_count);
        }
        const uint64_t bytes = count * sizeof(RayRecord);
        if (message.size() - at - kRayGroupHeaderBytes < bytes) {
            return DataLossError(
                "{}: group {} at byte {} holds {} rays ({} bytes) but the message ends at {}", what,
                g, at, count, bytes, message.size());
        }
        at += kRayGroupHeaderBytes + bytes;
    }
    if (at != message.size()) {
        return DataLossError("{}: {} bytes past the last of {} groups (message of {} bytes)", what,
                             message.size() - at, groups, message.size());
    }
    uint64_t rays = 0;
    std::vector<RayRecord> group;
    at = kRayMessageHeaderBytes;
    for (uint32_t g = 0; g < groups; ++g) {
        const uint32_t slot = GetU32(message.data() + at);
        const uint32_t count = GetU32(message.data() + at + 4);
        // Copied out: the bytes carry no RayRecord alignment.
        group.resize(count);
        std::memcpy(group.data(), message.data() + at + kRayGroupHeaderBytes,
                    count * sizeof(RayRecord));
        visit(slot, group);
        rays += count;
        at += kRayGroupHeaderBytes + count * sizeof(RayRecord);
    }
    return rays;
}

}  // namespace nave::render
