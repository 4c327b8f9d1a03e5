#include "src/render/stream/ray_message.h"

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

}  // namespace

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
