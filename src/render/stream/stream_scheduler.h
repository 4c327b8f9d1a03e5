#pragma once
// The stream scheduler (docs/render.md, "Scheduling"; docs/pager.md): the per-brick queues of rays
// in flight and the loop that drains them. Drain repeatedly picks a brick (the pager's choice, or a
// BrickPicker's), pins it through the pager, takes a batch of its rays and hands the batch to a
// RayProcessor on all threads; what the processor sends on is flushed, grouped by brick, to the
// RayExchange, which queues it at the brick's owner. The scheduler knows rays and bricks only: what
// happens to a ray inside a brick (shading, lights, the film) is the processor's, so paging is
// tuned here without touching the physics.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "src/core/status.h"
#include "src/render/bricks/brick_cache.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/stream/brick_picker.h"
#include "src/render/stream/pager.h"
#include "src/render/stream/ray.h"
#include "src/render/stream/ray_exchange.h"
#include "src/render/stream/ray_queue.h"
#include "src/render/stream/stream_stats.h"
#include "store/brick_tree.h"

namespace nave::render {

/// Work counted by the workers, summed into StreamStats by the scheduler (the same names).
struct RayCounts {
    /// Ray segments traced inside a brick (closest-hit queries).
    uint64_t segments_traced = 0;
    /// Shadow-ray segments traced inside a brick (occlusion queries).
    uint64_t shadow_segments = 0;
    /// Rays sent to another brick than the one they were traced or made in.
    uint64_t brick_moves = 0;
    /// Rays started: camera, continuation, shadow rays and photons.
    uint64_t rays = 0;
};

/// What one task produced: the rays it sends on (spawned, or leaving the brick's cell) and its
/// counts. One per task, so not thread-safe; StreamScheduler::Flush hands it to the exchange and
/// empties it.
struct RayOutbox {
    /// Holds `r` for brick `next` until the flush. A move when `next` is not `current`, the brick
    /// the ray was traced or made in (store::kNoBrick for rays made outside a batch, like camera
    /// rays).
    void Send(uint32_t next, uint32_t current, const RayRecord& r) {
        if (next != current) ++counts.brick_moves;
        rays.emplace_back(next, r);
    }

    std::vector<std::pair<uint32_t, RayRecord>> rays;  ///< (brick, ray), in the order sent
    RayCounts counts;
};

/// For a trace: the rays one batch sent to each other slot (a brick at a level of detail). Count
/// is thread-safe.
class SentPerBrick {
  public:
    /// Counts the rays of `out`, made by a batch of slot `from_slot`.
    void Count(uint32_t from_slot, const RayOutbox& out);
    /// "slot:rays slot:rays ...", by slot.
    std::string Text() const;

  private:
    std::mutex mutex_;
    std::map<uint32_t, uint64_t> counts_;
};

/// The work on the rays of one brick: what Drain does with a batch.
class RayProcessor {
  public:
    virtual ~RayProcessor() = default;
    /// Traces `rays`, taken from the queue of brick `brick` (pinned as `resident` for the call),
    /// and sends every ray that goes on in another brick to `out`. Called from many threads at
    /// once, each with its own part of the batch and its own outbox, which the scheduler flushes
    /// after the call.
    virtual void ProcessBatch(uint32_t brick, const ResidentBrick& resident,
                              std::span<const RayRecord> rays, RayOutbox& out) = 0;
};

/// Which level of each brick a pass over the whole model reads (StreamScheduler::ForEachBrick).
enum class ScanDetail {
    kFull,      ///< level 0: every triangle as stored
    kCoarsest,  ///< the coarsest level each brick has in use (level 0 without levels): a tenth of
                ///< the triangles to decode, and the level the render keeps resident first
};

/// The ray queues of one render and the loop that drains them. Acquire, Drain, SpillIfOverCap and
/// FillStats are called from the render's thread; Route and Flush from any thread (workers call
/// them).
class StreamScheduler {
  public:
    /// Schedules rays over the bricks of `source`, which must outlive the scheduler, with its
    /// bricks paged under `paging` (PagerOptions(): in-core, loaded in the background while the
    /// workers trace). `picker` empty: the pager's choice. `wave_paths`: camera paths (or photons)
    /// per wave, the unit of WaveOverlap. Errors: an impossible budget (the pager's
    /// ResourceExhausted error), spill files that cannot be made.
    /// `ranks` (null: one process) shares the bricks among the processes of a distributed render
    /// (BrickOwners): this scheduler traces the rays of its own bricks and sends the others'
    /// through the group's exchange; it must outlive the scheduler.
    static StatusOr<std::unique_ptr<StreamScheduler>> Create(BrickSource& source,
                                                             const PagerOptions& paging,
                                                             BrickPicker picker,
                                                             uint64_t wave_paths,
                                                             RankGroup* ranks = nullptr);
    ~StreamScheduler();
    StreamScheduler(const StreamScheduler&) = delete;
    StreamScheduler& operator=(const StreamScheduler&) = delete;

    /// Pins brick `brick` for a batch or a pass over the bricks, through the pager. Load errors
    /// name the brick.
    StatusOr<BrickHandle> Acquire(uint32_t brick);
    /// Pins every brick in turn, in order, for `visit` (a pass over the whole model before the
    /// render: the sky's portals, the light sources), at `detail`, while the pager's loaders load
    /// the next few: the loads then run on every core instead of one after another on this thread.
    /// `task` names the pass on its progress bar. In a distributed render only the bricks this
    /// process owns are visited: each process scans its own, and the caller gathers what it
    /// needs of the others'. Errors: a brick that cannot be pinned, `visit`'s.
    Status ForEachBrick(std::string_view task, ScanDetail detail,
                        const std::function<Status(uint32_t brick, const ResidentBrick&)>& visit);
    /// Sets r's segment to the first brick after `from_t` other than `current`'s; returns its slot
    /// at the level of detail r's footprint there chooses (level_choice.h), or store::kNoBrick
    /// (the ray leaves the model, or reaches t_max, first). `current` is a slot. With
    /// SkipBricksCrossedInAir, a brick whose full mesh r's segment cannot meet
    /// (BrickSource::Occupancy) is passed over as a trace there would miss it.
    uint32_t Route(RayRecord& r, float from_t, uint32_t current) const;
    /// Where the paging options ask for it (PagerOptions::skip_air), Route passes over the
    /// full-detail bricks a ray crosses only through empty voxels of their occupancy grids
    /// (docs/pager.md, "Rays that cross a brick's air"): for renders without a medium, whose rays
    /// do nothing between surfaces (a medium's flight over a passed brick would be drawn over
    /// another stretch).
    /// Where the source does not know the bricks' grids, they are made from then on
    /// (BrickSource::MakeOccupancyGrids), and only then.
    void SkipBricksCrossedInAir() {
        skip_air_ = skip_air_allowed_;
        source_.MakeOccupancyGrids(skip_air_ && !source_.occupancy_known());
    }
    /// Whether this process makes ray `r`, one of the rays made outside a batch (a camera ray or
    /// a photon, `index` its pixel or photon): every process makes them all in the same way and
    /// keeps those whose first brick it owns, and of those that meet no brick, every size-th
    /// index. One process: always.
    bool MakesHere(RayRecord r, uint64_t index) const;
    /// The processes of a distributed render (null: one process).
    RankGroup* ranks() const { return ranks_; }
    /// Where rays leaving a batch go: this process's queues, or the group's exchange.
    RayExchange& exchange() const { return *exchange_; }
    /// Sends the rays of `out` to the exchange, grouped by brick, adds its counts to the render's
    /// and empties it.
    void Flush(RayOutbox& out);
    /// Runs the scheduler until at most `stop_below` rays wait (0: every queue is empty), tracing
    /// every batch with `processor`. Errors: a brick that cannot be pinned.
    Status Drain(RayProcessor& processor, size_t stop_below = 0);
    /// Runs the scheduler, as Drain does, until no ray of a round before `round` is left, the
    /// round of a ray being RoundOfPass of its sample index: the rays of later rounds are traced
    /// meanwhile (the fullest brick first, as always) and may stay in flight. A render that learns
    /// in rounds then waits for the round it learns from without draining the one after it, whose
    /// tail, a few rays over many bricks, rides on the next round's loads instead of costing loads
    /// of its own. A distributed render drains completely instead (its processes count no rounds),
    /// as does a scheduler that was not asked to count rounds.
    Status DrainRoundsBefore(RayProcessor& processor, uint32_t round);
    /// Counts the rays waiting per round from now on, for DrainRoundsBefore: for renders whose
    /// rays' sample index is a pass (path mode); photon mode's sample indices are not, and it has
    /// no use for the counts. Call before the first ray is queued.
    void CountRoundsOfPasses() { count_rounds_ = true; }
    /// How the last wave of DrainInWaves ends: with its tail still in flight (the next pass's first
    /// wave joins it), or drained to the last ray.
    enum class LastWave { kTailInFlight, kDrained };
    /// `count` paths (or photons) in waves of `wave_paths`: `generate(first, last)` queues the rays
    /// of paths [first, last), and each wave is drained by `processor` until WaveOverlap rays
    /// wait, so that the next wave joins its tail; the last wave as `last` says. Errors: those of
    /// `generate` and Drain.
    Status DrainInWaves(RayProcessor& processor, uint64_t count, uint64_t wave_paths, LastWave last,
                        const std::function<Status(uint64_t first, uint64_t last)>& generate);
    /// Spills queues to disk if they hold more than the queue memory cap (a no-op in-core).
    /// For the integrators between chunks of a wave's new rays, so that a wave larger than the cap
    /// is spilled as it is generated rather than queued whole first. Not concurrent with Drain or
    /// Flush.
    Status SpillIfOverCap();
    /// Camera paths to generate between two SpillIfOverCap calls: as many as a batch takes, for
    /// which the queue reserve has room (MaxBatchRays, memory_plan.h).
    size_t generate_chunk() const { return max_batch_; }
    /// Rays left waiting when the next wave is generated: under a budget the next wave joins the
    /// tail of the previous one, whose few scattered rays would otherwise cost a load each
    /// (docs/pager.md); in-core, waves do not overlap.
    size_t WaveOverlap() const;
    /// Fills `stats` (rays, segments, brick moves, batches, bytes read, residency, peak queue
    /// bytes, brick cache, spilling). `before`: the source's counters when the render started.
    void FillStats(const BrickSourceStats& before, StreamStats* stats) const;
    /// In a distributed render, after FillStats: sums the counts of `stats` over the processes
    /// (residency stays this process's) and adds the exchange's, checking that every ray sent
    /// was received. Collective. One process: nothing to do.
    Status SumStatsOverRanks(StreamStats* stats) const;

    /// In a distributed render, after a complete drain (collective): when the busiest process
    /// spent more than kRebalanceRatio times the mean on its batches since the last call, the
    /// bricks go to new owners cut by their work (BrickOwnersByWork; summed over the processes,
    /// brick by brick, the work on the slots every process holds credited to the bricks whose
    /// rays entered them) and the processes above the mean hand a share of the rays entering
    /// those slots to the processes below it (SpreadOfSharedWork), if that makes the busiest
    /// lighter; bricks a process no longer owns leave its memory. One process: nothing to do.
    Status Rebalance();
    /// The busiest process's work over the mean above which Rebalance moves bricks.
    static constexpr double kRebalanceRatio = 1.2;
    /// Times Rebalance moved bricks.
    int rebalances() const { return rebalances_; }

    /// In a distributed render whose group holds coarse levels everywhere
    /// (RankGroup::coarse_levels_everywhere): whether the rays bound for the coarse levels the
    /// pager keeps resident are traced in the process they are in (`here`, the default) or sent
    /// to their brick's owner from the next drain on. A photon pass needs the owner, whose
    /// visible points its photons reach. Between complete drains, in every process at once. One
    /// process, or a group that does not hold them everywhere: nothing to do.
    Status TraceCoarseLevelsHere(bool here);

    /// The bricks the rays are scheduled over (slots: bricks at their levels of detail).
    const BrickSource& source() const { return source_; }
    /// The source's brick tree, along which rays are routed.
    const store::BrickTree& tree() const { return tree_; }

  private:
    StreamScheduler(BrickSource& source, BrickPicker picker, uint64_t wave_paths, RankGroup* ranks);
    /// Sets the source up for `paging` (BVH settings, decode limit, brick cache), makes the queues'
    /// spill file and starts the pager.
    Status StartPaging(const PagerOptions& paging);
    /// SpillIfOverCap with the rays waiting per brick already counted.
    Status SpillIfOverCap(const std::vector<size_t>& waiting);
    /// Spills queues of bricks that are not resident until their memory is below half the cap.
    Status SpillQueues(const std::vector<size_t>& waiting);
    /// Drain, which also stops once no ray of a round before `rounds_before` is left (0: no
    /// such stop).
    Status DrainUntil(RayProcessor& processor, size_t stop_below, uint32_t rounds_before);
    /// Rays waiting in this process's queues of rounds before `round`.
    uint64_t WaitingBeforeRound(uint32_t round) const;
    /// Counts `count` rays of `rays` queued (+1) or taken (-1) in waiting_by_round_.
    void CountRounds(std::span<const RayRecord> rays, int64_t sign);

    BrickSource& source_;
    const store::BrickTree& tree_;
    const BrickPicker picker_;  // empty: the pager picks
    const uint64_t wave_paths_;
    BrickQueues<RayRecord> queues_;
    LocalRayExchange local_exchange_{queues_};
    RankGroup* const ranks_;
    std::unique_ptr<RayExchange> distributed_exchange_;  // with ranks_: the group's
    RayExchange* exchange_ = &local_exchange_;  // every ray leaving a batch goes through here

    // Under a budget: queue blocks spilled to disk beyond queue_memory_ (null: none).
    std::unique_ptr<store::SpillFile> queue_spill_;
    uint64_t queue_memory_ = 0;
    uint64_t spilled_rays_ = 0;
    size_t max_batch_;  // rays taken from a queue per batch
    // Under a budget: decoded meshes of loaded bricks, for their reloads (null: none). Outlives
    // the pager, whose loaders read and write it.
    std::unique_ptr<BrickCache> brick_cache_;
    // Declared after queues_, so destroyed first: its loader thread reads the queues until joined.
    std::unique_ptr<Pager> pager_;
    TraceRecorder* trace_ = nullptr;
    // Per slot, microseconds of this process's batches of it (pinning, loads waited for and
    // tracing) since the last Rebalance: the work that re-balancing shares out. The slots every
    // process traces are summed apart, with the rays each brick's own slots sent them: Rebalance
    // credits that work to the bricks whose rays it was.
    std::vector<uint64_t> work_us_;
    uint64_t everywhere_work_us_ = 0;
    std::vector<uint64_t> into_everywhere_;  // per brick
    // The fraction of the rays this process's bricks send into the slots every process holds that
    // each process traces (SpreadOfSharedWork; empty: all here), set by Rebalance.
    std::vector<double> spread_;
    /// Takes out of `out` the rays entering the slots every process holds that spread_ hands to
    /// other processes, and sends them there; returns how many rays entered those slots.
    uint64_t SpreadIntoEverywhere(RayOutbox& out);
    // Distributed: each slot's owner by brick (BrickOwners, then Rebalance), the slots every
    // process holds when coarse levels are traced where the rays are (KeptLevels; empty when the
    // group does not), and whether they are now (TraceCoarseLevelsHere).
    std::vector<int> brick_owners_;
    std::vector<bool> everywhere_;
    bool coarse_here_ = false;
    /// brick_owners_ with the slots of everywhere_ owned by kEveryRank while coarse_here_.
    std::vector<int> SlotOwners() const;
    int rebalances_ = 0;
    int rounds_overlapped_ = 0;
    std::atomic<uint64_t> segments_traced_{0}, shadow_segments_{0}, brick_moves_{0}, batches_{0},
        rays_{0};
    // One process: the rays waiting in the queues per round (RoundOfPass of their sample index,
    // 0..32), for DrainRoundsBefore.
    static constexpr size_t kRounds = 33;
    /// The level Route gives r in `brick`, r's segment there already set.
    uint32_t LevelOfSegment(const RayRecord& r, uint32_t brick) const;

    bool count_rounds_ = false;
    bool skip_air_allowed_ = false;  // PagerOptions::skip_air, with what the source knows
    bool skip_air_ = false;          // SkipBricksCrossedInAir
    std::array<std::atomic<int64_t>, kRounds> waiting_by_round_{};
};

}  // namespace nave::render
