#pragma once
// Who owns a brick, seen from the scheduler: the place rays bound for the brick are handed to. The
// stream scheduler never pushes to a queue itself; it sends every ray leaving a batch (spawned, or
// crossing into another brick's cell) to a RayExchange, grouped by the brick its next segment lies
// in, and drains its own queues. In one process every brick is owned here and sending is a push
// onto the brick's queue (LocalRayExchange); bricks owned by several processes need an exchange
// that forwards the rays of the bricks owned elsewhere to their owner.

#include <cstdint>
#include <span>

#include "src/render/stream/ray.h"
#include "src/render/stream/ray_queue.h"

namespace nave::render {

/// Delivers rays to the owner of the brick their next segment lies in.
class RayExchange {
  public:
    virtual ~RayExchange() = default;
    /// Hands `rays`, whose next segments all lie in brick `brick`, to the brick's owner. The rays
    /// are copied: the caller may reuse the span's storage after the call. Thread-safe: every
    /// worker flushing its outbox calls it.
    virtual void Send(uint32_t brick, std::span<const RayRecord> rays) = 0;
};

/// The exchange of a single process: it owns every brick, and rays sent to a brick wait in its
/// queue.
class LocalRayExchange final : public RayExchange {
  public:
    /// `queues` must outlive the exchange.
    explicit LocalRayExchange(BrickQueues<RayRecord>& queues) : queues_(queues) {}

    void Send(uint32_t brick, std::span<const RayRecord> rays) override {
        queues_.Push(brick, rays.data(), rays.size());
    }

  private:
    BrickQueues<RayRecord>& queues_;
};

}  // namespace nave::render
