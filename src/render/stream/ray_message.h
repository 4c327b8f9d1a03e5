#pragma once
// The bytes of one message of rays between the ranks of a distributed render
// (docs/distributed.md): groups of rays, each for one brick slot. The format is the ranks' own
// (they run the same nave), so records travel as they lie in memory; what is checked on receipt is
// that the message is whole and every group names a slot, so that a damaged or foreign message is
// an error naming its sender rather than rays in the wrong brick.
//
//   u32 version (kRayMessageVersion), u32 group count,
//   then per group: u32 slot, u32 ray count, ray count x sizeof(RayRecord) bytes.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "src/core/status.h"
#include "src/render/stream/ray.h"

namespace nave::render {

inline constexpr uint32_t kRayMessageVersion = 1;
/// Bytes of a message's header, and of each group's.
inline constexpr size_t kRayMessageHeaderBytes = 8;
inline constexpr size_t kRayGroupHeaderBytes = 8;

/// A message being filled: groups appended one after another.
class RayMessage {
  public:
    RayMessage();
    /// Appends a group of `rays` (at most 2^32 - 1) for slot `slot`.
    void Append(uint32_t slot, std::span<const RayRecord> rays);
    /// Rays appended since the message was made or taken.
    uint64_t ray_count() const { return rays_; }
    size_t size_bytes() const { return bytes_.size(); }
    bool empty() const { return rays_ == 0; }
    /// The finished message; this one starts empty again.
    std::vector<std::byte> Take();

  private:
    std::vector<std::byte> bytes_;
    uint32_t groups_ = 0;
    uint64_t rays_ = 0;
};

/// The version word of a message packed for the wire (PackRayMessage).
inline constexpr uint32_t kPackedRayMessageVersion = 2;

/// `raw` (a RayMessage::Take) packed for the wire: each group's records transposed byte by byte
/// (the bytes at one offset of every record side by side: kinds, depths, pixel rows, the exponents
/// of nearby positions, which LZ4 then finds repeated), then LZ4 (one block):
///
///   u32 version (kPackedRayMessageVersion), u32 raw size, the LZ4 block.
std::vector<std::byte> PackRayMessage(std::span<const std::byte> raw);
/// Whether `message` is packed (PackRayMessage) rather than raw.
bool IsPackedRayMessage(std::span<const std::byte> message);
/// The raw message `packed` holds, into `raw`. Errors (kDataLoss, prefixed by `what`): a raw size
/// over `max_raw_bytes`, a block LZ4 cannot decompress to it. Groups that do not fit are left for
/// ForEachRayGroup to report.
Status UnpackRayMessage(std::span<const std::byte> packed, size_t max_raw_bytes,
                        std::string_view what, std::vector<std::byte>* raw);

/// Calls `visit(slot, rays)` for each group of `message`, in order; returns the rays visited.
/// Errors (kDataLoss, prefixed by `what`, e.g. "rays from rank 2"): another version, a message cut
/// short or with bytes past its last group, a slot >= `slot_count`; nothing is visited then.
StatusOr<uint64_t> ForEachRayGroup(
    std::span<const std::byte> message, uint32_t slot_count, std::string_view what,
    const std::function<void(uint32_t slot, std::span<const RayRecord> rays)>& visit);

}  // namespace nave::render
