#pragma once
// Who owns a brick, seen from the scheduler: the place rays bound for the brick are handed to. The
// stream scheduler never pushes to a queue itself; it sends every ray leaving a batch (spawned, or
// crossing into another brick's cell) to a RayExchange, grouped by the brick its next segment lies
// in, and drains its own queues. In one process every brick is owned here and sending is a push
// onto the brick's queue (LocalRayExchange); bricks owned by several processes need an exchange
// that forwards the rays of the bricks owned elsewhere to their owner.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "src/core/status.h"
#include "src/render/stream/ray.h"
#include "src/render/stream/ray_queue.h"

namespace nave {
class ProgressBar;
}

namespace nave::render {

/// What the exchange of a distributed render did: one process's, or (TotalCounts) every one's
/// summed.
struct ExchangeCounts {
    uint64_t records_sent = 0;      ///< rays sent to other processes
    uint64_t records_received = 0;  ///< rays received from other processes and queued here
    uint64_t messages_sent = 0;
    uint64_t messages_received = 0;
    uint64_t bytes_sent = 0;
    uint64_t bytes_received = 0;
    uint64_t termination_rounds = 0;  ///< rounds of the sum that detects the end of a drain
    double idle_seconds = 0;          ///< time waiting for rays with none to trace
};

/// The owner of a slot every process holds (a coarse level of detail kept resident on every rank,
/// docs/distributed.md "Coarse levels on every rank"): rays bound for it are traced where they are.
inline constexpr int kEveryRank = -1;

/// Whether `rank` traces the rays of a slot owned by `owner`.
inline bool TracedBy(int owner, int rank) { return owner == rank || owner == kEveryRank; }

/// Delivers rays to the owner of the brick their next segment lies in.
class RayExchange {
  public:
    virtual ~RayExchange() = default;
    /// Hands `rays`, whose next segments all lie in brick `brick`, to the brick's owner. The rays
    /// are copied: the caller may reuse the span's storage after the call. Thread-safe: every
    /// worker flushing its outbox calls it.
    virtual void Send(uint32_t brick, std::span<const RayRecord> rays) = 0;
    /// Hands `rays`, bound for a slot every process holds (kEveryRank), to process `rank` to
    /// trace: how an overloaded process shares that work (StreamScheduler::Rebalance). As Send.
    virtual void SendToRank(int rank, uint32_t slot, std::span<const RayRecord> rays) = 0;
    /// Whether this process traces the rays of brick `brick`: it owns it, or every process does.
    virtual bool Owns(uint32_t brick) const = 0;
    /// The process that owns brick `brick` (0 in a render of one process; kEveryRank for a slot
    /// every process holds).
    virtual int Owner(uint32_t brick) const = 0;
    /// Hands the bricks to new owners (`owners[s]`: the process of slot s, or kEveryRank), the
    /// same in every process. Only between drains, with no ray waiting or in flight anywhere. One
    /// process: Unsupported (it owns every brick).
    virtual Status SetOwners(std::vector<int> owners) = 0;
    /// Delivers the rays that have arrived from elsewhere to their queues; called between batches.
    virtual Status Progress() { return Status::Ok(); }
    /// For a process whose queues are empty: waits until rays arrive (false) or no process has a
    /// ray left or in flight (true, in every process at once). One process: true at once.
    virtual StatusOr<bool> WaitForRaysOrEnd() { return true; }
    /// Every process's counts summed, and the closing check: every ray sent was received
    /// (kInternal naming both sums otherwise). Collective, after the last drain. One process:
    /// nothing sent.
    virtual StatusOr<ExchangeCounts> TotalCounts() const { return ExchangeCounts{}; }
    /// Work counted where it ends (a path ends in the process that traces its last ray) on
    /// `bar`, which the first process shows: while rays are traced and awaited, the other
    /// processes report what was added to their `bar` since their last report, and the first adds
    /// the reports to its own, so that the bar the user sees counts the whole job. `bar` must
    /// outlive the sharing; null stops it. One process: nothing to share.
    virtual void ShareProgress(ProgressBar* bar) { (void)bar; }
    /// After the last drain of the work `bar` counts: the last reports are sent and added, then
    /// the sharing stops. Collective. One process: nothing to do.
    virtual Status FinishProgress() { return Status::Ok(); }
};

/// The processes of a distributed render as the renderer sees them (docs/distributed.md): their
/// number, this one's rank, an exchange of rays among them and sums over them. Implemented over MPI
/// (mpi_rank_group.h) where nave is built with it. Every method but rank and size is collective:
/// every process calls it, in the same order.
class RankGroup {
  public:
    virtual ~RankGroup() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    /// Whether every process holds the coarse levels of detail the pager keeps resident and traces
    /// the rays bound for them itself (kEveryRank), instead of sending them to the brick's owner
    /// (docs/distributed.md, "Coarse levels on every rank").
    virtual bool coarse_levels_everywhere() const = 0;
    /// The exchange for `queues` (which must outlive it), brick slot s owned by rank owners[s]
    /// (kEveryRank: by every one).
    virtual StatusOr<std::unique_ptr<RayExchange>> MakeExchange(std::vector<int> owners,
                                                                BrickQueues<RayRecord>& queues) = 0;
    /// Replaces `values` by their sums over the processes, in every process.
    virtual Status SumEverywhere(std::span<double> values) = 0;
    virtual Status SumEverywhere(std::span<float> values) = 0;
    virtual Status SumEverywhere(std::span<uint32_t> values) = 0;
    virtual Status SumEverywhere(std::span<uint64_t> values) = 0;
    /// Every process's `mine` put end to end in rank order, in every process. Errors: more than
    /// 2 GiB in all (MPI counts bytes in an int). Collective.
    virtual StatusOr<std::vector<std::byte>> GatherEverywhere(std::span<const std::byte> mine) = 0;
    /// Sends `to_rank[r]` to process r (one entry per process; this process's own is kept as
    /// is) and returns what every process sent to this one, end to end in rank order. Errors:
    /// more than 2 GiB to send or to receive (MPI counts bytes in an int). Collective.
    virtual StatusOr<std::vector<std::byte>> SendToEach(
        std::span<const std::vector<std::byte>> to_rank) = 0;
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
    void SendToRank(int /*rank*/, uint32_t slot, std::span<const RayRecord> rays) override {
        Send(slot, rays);
    }
    bool Owns(uint32_t) const override { return true; }
    int Owner(uint32_t) const override { return 0; }
    Status SetOwners(std::vector<int> /*owners*/) override {
        return UnsupportedError("one process owns every brick");
    }

  private:
    BrickQueues<RayRecord>& queues_;
};

}  // namespace nave::render
