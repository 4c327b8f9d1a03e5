#pragma once
// The ray exchange of a distributed render (docs/distributed.md): the bricks are shared among the
// ranks of an MPI job, and a ray bound for a brick another rank owns is appended to that rank's
// next message, which goes out with a non-blocking send once it is full (or when this rank runs out
// of rays), while the workers trace on. A rank that has run out of rays takes part in rounds of a
// non-blocking sum of the records every rank has sent and received: the rays in flight have all
// arrived, and every rank is idle, when two rounds in a row find sent = received and nothing
// changed between them (Mattern 1987, "Algorithms for distributed termination detection", the
// four-counter method). Built only where MPI is found (NAVE_HAVE_MPI); no MPI type leaves
// mpi_ray_exchange.cpp.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "src/core/status.h"
#include "src/render/stream/ray.h"
#include "src/render/stream/ray_exchange.h"
#include "src/render/stream/ray_queue.h"

namespace nave::render {

/// How the exchange batches and paces its messages.
struct MpiExchangeOptions {
    /// A message to one rank goes out once it holds this many bytes (8 k rays of 128 bytes): large
    /// enough that a message's latency is small beside its transfer on Gigabit Ethernet.
    size_t message_bytes = size_t(1) << 20;
    /// Sends to one rank posted and not yet complete, at most: past it, Progress waits (receiving
    /// meanwhile), so a slow rank holds its senders back instead of their memory filling up.
    int max_sends_in_flight = 8;
    /// Pack messages for the wire (PackRayMessage: records transposed byte by byte, then LZ4), a
    /// few times fewer bytes for a little CPU time: for networks slower than the ranks' tracing
    /// (Gigabit Ethernet; docs/distributed.md, "Replay").
    bool pack_messages = true;
    /// A rank with no ray to trace that waits this long with nothing arriving and no round of the
    /// end-of-drain sum completing ends the job with an error naming itself and the wait (a rank
    /// that stopped, or a batch longer than this): a job never hangs. 0: waits for ever.
    double stall_timeout_s = 600;
    /// Every rank holds the coarse levels of detail kept resident and traces their rays where
    /// they are (RankGroup::coarse_levels_everywhere): on the detail-30 abbey with levels, 4 ranks
    /// sent 18.1 k rays to each other instead of 341 k (docs/distributed.md).
    bool coarse_levels_everywhere = true;
};

/// The exchange between the ranks of MPI_COMM_WORLD (on a duplicate of it, so that its messages
/// meet no one else's). Send is thread-safe and makes no MPI call; every other method is called
/// from the thread that made the exchange, which MPI must allow (MPI_THREAD_FUNNELED or more:
/// MpiRuntime). Methods marked collective are called by every rank, in the same order.
class MpiRayExchange final : public RayExchange {
  public:
    /// `owners[s]`: the rank that owns brick slot s (the queues' index), or kEveryRank; rays of
    /// the slots this rank traces are pushed onto `queues`, which must outlive the exchange.
    /// Errors: MPI not initialized, an owner outside [0, ranks) other than kEveryRank, a slot
    /// count other than the queues'. Collective.
    static StatusOr<std::unique_ptr<MpiRayExchange>> Create(std::vector<int> owners,
                                                            BrickQueues<RayRecord>& queues,
                                                            const MpiExchangeOptions& options = {});
    ~MpiRayExchange() override;
    MpiRayExchange(const MpiRayExchange&) = delete;
    MpiRayExchange& operator=(const MpiRayExchange&) = delete;

    int rank() const;
    int size() const;
    /// The rank that owns slot `slot`.
    int Owner(uint32_t slot) const override;
    bool Owns(uint32_t slot) const override { return TracedBy(Owner(slot), rank()); }
    /// Errors: a slot count other than the queues', an owner outside [0, ranks), a message not yet
    /// sent.
    Status SetOwners(std::vector<int> owners) override;

    /// Queues rays of this rank's slots; appends the others to their owner's next message.
    void Send(uint32_t slot, std::span<const RayRecord> rays) override;
    /// Appends rays of a slot every rank holds to rank `dest`'s next message (queues them if
    /// `dest` is this one).
    void SendToRank(int dest, uint32_t slot, std::span<const RayRecord> rays) override;
    /// Posts the messages that are full, completes finished sends and queues the rays that have
    /// arrived. Called between batches. Errors: a message that is not whole (names the sender),
    /// an MPI error.
    Status Progress() override;
    /// For a rank whose queues are empty: sends what its messages hold, then waits until rays
    /// arrive (returns false: trace them, then call again) or every rank is idle with no ray in
    /// flight (returns true, on every rank in the same call). Collective. Errors: kInternal after
    /// stall_timeout_s with nothing arriving and no round completing, naming this rank and the
    /// wait.
    StatusOr<bool> WaitForRaysOrEnd() override;
    /// Every rank's counts summed, and the closing check: every record sent was received. Errors:
    /// kInternal naming both sums when they differ. Collective; call after WaitForRaysOrEnd
    /// returned true.
    StatusOr<ExchangeCounts> TotalCounts() const override;
    /// Reports go to rank 0 as small messages of their own, at most every half second per rank.
    void ShareProgress(ProgressBar* bar) override;
    Status FinishProgress() override;

  private:
    struct Impl;
    explicit MpiRayExchange(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace nave::render
