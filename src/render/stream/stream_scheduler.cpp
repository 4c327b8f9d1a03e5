#include "src/render/stream/stream_scheduler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <numeric>
#include <tuple>

#include "src/core/check.h"
#include "src/core/log.h"
#include "src/core/progress.h"
#include "src/core/trace.h"
#include "src/render/bricks/brick_walk.h"
#include "src/render/stream/brick_owners.h"
#include "src/render/stream/level_choice.h"
#include "src/render/stream/memory_plan.h"

namespace nave::render {
namespace {

/// Rays per task within a batch.
constexpr size_t kChunk = 256;

}  // namespace

StreamScheduler::StreamScheduler(BrickSource& source, BrickPicker picker, uint64_t wave_paths,
                                 RankGroup* ranks)
    : source_(source),
      tree_(source.tree()),
      picker_(std::move(picker)),
      wave_paths_(wave_paths),
      queues_(source.slot_count()),
      ranks_(ranks),
      max_batch_(MaxBatchRays(0)),
      work_us_(source.slot_count(), 0),
      into_everywhere_(source.brick_count(), 0) {}

StreamScheduler::~StreamScheduler() {
    pager_.reset();  // joins the loaders before the cache they use goes
    if (brick_cache_) source_.SetBrickCache(nullptr);
    source_.SetDecodeLimit(0);
}

StatusOr<std::unique_ptr<StreamScheduler>> StreamScheduler::Create(BrickSource& source,
                                                                   const PagerOptions& paging,
                                                                   BrickPicker picker,
                                                                   uint64_t wave_paths,
                                                                   RankGroup* ranks) {
    std::unique_ptr<StreamScheduler> scheduler(
        new StreamScheduler(source, std::move(picker), wave_paths, ranks));
    scheduler->skip_air_allowed_ =
        paging.skip_air == PagerOptions::SkipAir::kOn ||
        (paging.skip_air == PagerOptions::SkipAir::kAuto && source.occupancy_known());
    NAVE_RETURN_IF_ERROR(scheduler->StartPaging(paging));
    if (ranks != nullptr) {
        scheduler->brick_owners_ = BrickOwners(source, ranks->size());
        if (ranks->coarse_levels_everywhere()) {
            // The levels each process's pager keeps (the same budget in every process): kept
            // everywhere, their rays need not travel.
            scheduler->everywhere_ = scheduler->pager_->kept();
            scheduler->coarse_here_ = true;
        }
        NAVE_ASSIGN_OR_RETURN(scheduler->distributed_exchange_,
                              ranks->MakeExchange(scheduler->SlotOwners(), scheduler->queues_));
        scheduler->exchange_ = scheduler->distributed_exchange_.get();
    }
    return scheduler;
}

bool StreamScheduler::MakesHere(RayRecord r, uint64_t index) const {
    if (ranks_ == nullptr) return true;
    const uint32_t first = Route(r, 0, store::kNoBrick);
    // A ray that meets no brick, or whose first brick every process holds, is made by one
    // process chosen by its index.
    if (first == store::kNoBrick || exchange_->Owner(first) == kEveryRank)
        return index % uint64_t(ranks_->size()) == uint64_t(ranks_->rank());
    return exchange_->Owns(first);
}

std::vector<int> StreamScheduler::SlotOwners() const {
    std::vector<int> owners = brick_owners_;
    if (coarse_here_) {
        for (size_t s = 0; s < owners.size() && s < everywhere_.size(); ++s)
            if (everywhere_[s]) owners[s] = kEveryRank;
    }
    return owners;
}

Status StreamScheduler::TraceCoarseLevelsHere(bool here) {
    if (ranks_ == nullptr || everywhere_.empty() || here == coarse_here_) return Status::Ok();
    coarse_here_ = here;
    return exchange_->SetOwners(SlotOwners());
}

Status StreamScheduler::StartPaging(const PagerOptions& paging) {
    NAVE_RETURN_IF_ERROR(source_.SetBvhSettings(paging.bvh));
    source_.SetTrace(paging.trace);
    // Under a budget one decode runs at a time: its scratch memory is reserved once (the memory
    // plan counts LoadScratchBytes), and with the brick cache only first loads decode.
    if (!paging.in_core()) source_.SetDecodeLimit(1);
    if (!paging.in_core() && paging.brick_cache) {
        NAVE_ASSIGN_OR_RETURN(std::unique_ptr<store::SpillFile> file,
                              store::SpillFile::Create(paging.spill_dir, "the brick cache"));
        uint64_t limit = paging.brick_cache_limit_bytes;
        if (limit == 0) {
            std::error_code ec;
            const std::filesystem::space_info space = std::filesystem::space(file->dir(), ec);
            limit = ec ? 0 : space.available / 2;
        }
        brick_cache_ = std::make_unique<BrickCache>(std::move(file), source_.slot_count(), limit);
        source_.SetBrickCache(brick_cache_.get());
    }
    const uint64_t queue_memory = QueueMemoryBytes(paging);
    if (!paging.in_core() && queue_memory > 0) {
        NAVE_ASSIGN_OR_RETURN(queue_spill_,
                              store::SpillFile::Create(paging.spill_dir, "the ray queues"));
        queue_memory_ = queue_memory;
        max_batch_ = MaxBatchRays(queue_memory_);
    }
    trace_ = paging.trace;
    if (trace_ != nullptr) trace_->NameThread("scheduler");
    NAVE_ASSIGN_OR_RETURN(
        pager_, Pager::Create(source_, paging, [this](uint32_t b) { return queues_.Waiting(b); }));
    if (trace_ != nullptr) {
        // For a replay of the render over several processes (bench/replay_mpi.py): the order in
        // which BrickOwners cuts runs of bricks, how many slots there are to a brick, and the
        // slots the pager keeps resident (which processes may hold everywhere).
        auto join = [](const auto& numbers) {
            std::string text;
            for (uint32_t n : numbers) {
                if (!text.empty()) text += ' ';
                text += std::to_string(n);
            }
            return text;
        };
        std::vector<uint32_t> kept_slots;
        for (uint32_t s = 0; s < pager_->kept().size(); ++s)
            if (pager_->kept()[s]) kept_slots.push_back(s);
        trace_->Instant("bricks", "scheduler",
                        {{"bricks", source_.brick_count()},
                         {"depth_first", join(BricksDepthFirst(source_))},
                         {"kept", join(kept_slots)}});
    }
    return Status::Ok();
}

StatusOr<BrickHandle> StreamScheduler::Acquire(uint32_t brick) { return pager_->Acquire(brick); }

Status StreamScheduler::ForEachBrick(
    std::string_view task, ScanDetail detail,
    const std::function<Status(uint32_t brick, const ResidentBrick&)>& visit) {
    // How many bricks past the one visited the loaders may fetch: enough to keep both loaders
    // busy, few enough that a small budget does not evict them before their turn.
    constexpr uint32_t kAhead = 4;
    const uint32_t count = source_.brick_count();
    ProgressBar progress(std::string(task), count, "bricks");
    std::vector<size_t> ahead(source_.slot_count(), 0);
    const auto slot_of = [&](uint32_t b) {
        return source_.SlotOf(b, detail == ScanDetail::kFull ? 0 : source_.LevelsOf(b) - 1);
    };
    // A process of a distributed render reads its own bricks only (the others read theirs), at
    // whatever level: a brick is its full mesh's owner's, even where every process holds its
    // coarse level.
    std::vector<uint32_t> bricks;
    for (uint32_t b = 0; b < count; ++b) {
        if (exchange_->Owns(source_.SlotOf(b, 0))) bricks.push_back(b);
    }
    if (bricks.size() != count) progress.SetTotal(bricks.size());
    for (size_t i = 0; i < bricks.size(); ++i) {
        const uint32_t b = bricks[i];
        const uint32_t slot = slot_of(b);
        // The next bricks, the nearest ranked first, as if rays waited for them.
        ahead[slot] = 0;
        for (size_t n = i + 1; n < std::min(bricks.size(), i + 1 + kAhead); ++n)
            ahead[slot_of(bricks[n])] = kAhead + 1 - (n - i);
        pager_->Prefetch(ahead, slot, 0);
        NAVE_ASSIGN_OR_RETURN(BrickHandle handle, Acquire(slot));
        NAVE_RETURN_IF_ERROR(visit(b, *handle));
        handle.Reset();
        pager_->BatchDone();
        progress.Add(1);
    }
    // Nothing ahead any more: the loaders wait for the render's queues.
    std::fill(ahead.begin(), ahead.end(), 0);
    pager_->Prefetch(ahead, store::kNoBrick, 0);
    progress.Finish();
    return Status::Ok();
}

uint32_t StreamScheduler::Route(RayRecord& r, float from_t, uint32_t current) const {
    uint32_t current_brick = current == store::kNoBrick ? current : source_.BrickOfSlot(current);
    for (;;) {
        const BrickSegment s = NextBrick(tree_, r.origin, r.dir, from_t, r.t_max, current_brick);
        r.t_enter = s.t_enter;
        r.t_exit = s.t_exit;
        if (s.brick == store::kNoBrick) return s.brick;
        const uint32_t level = LevelOfSegment(r, s.brick);
        if (level == 0 && skip_air_) {
            // At full detail a segment ends where TraceInBrick's does (SegmentEnd, no overlap).
            const store::OccupancyGrid* grid = source_.Occupancy(s.brick);
            if (grid != nullptr &&
                grid->SegmentEmpty(r.origin, r.dir, s.t_enter,
                                   std::min(SegmentEndWithSlack(s.t_exit), r.t_max))) {
                from_t = s.t_exit;
                current_brick = s.brick;
                continue;
            }
        }
        return source_.SlotOf(s.brick, level);
    }
}

uint32_t StreamScheduler::LevelOfSegment(const RayRecord& r, uint32_t brick) const {
    if (source_.level_count() == 1 || !UsesLevels(r)) return 0;
    // Near its origin, and in the whole brick it starts in, a ray keeps the level of the surface
    // it leaves: that level's copy of the surface is the one it leaves, and another level's could
    // lie on either side of it (LevelReach). Elsewhere its footprint chooses, where it enters the
    // cell: the footprint is narrowest there, so every hit inside is at least as wide.
    const bool near_origin = r.t_enter == 0 || r.t_enter < r.level_reach;
    return near_origin ? std::min<uint32_t>(r.origin_level, source_.LevelsOf(brick) - 1)
                       : ChooseLevel(source_.LevelErrors(brick), source_.level_count(),
                                     ConeWidthAt(r, r.t_enter));
}

void SentPerBrick::Count(uint32_t from_slot, const RayOutbox& out) {
    std::map<uint32_t, uint64_t> mine;
    for (const auto& [slot, ray] : out.rays) {
        if (slot != from_slot) ++mine[slot];
    }
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [to, n] : mine) counts_[to] += n;
}

std::string SentPerBrick::Text() const {
    std::string text;
    for (const auto& [to, n] : counts_) {
        if (!text.empty()) text += ' ';
        text += std::to_string(to) + ':' + std::to_string(n);
    }
    return text;
}

void StreamScheduler::CountRounds(std::span<const RayRecord> rays, int64_t sign) {
    if (!count_rounds_ || ranks_ != nullptr) return;
    std::array<int64_t, kRounds> n{};
    for (const RayRecord& r : rays) ++n[RoundOfPass(r.sample)];
    for (size_t k = 0; k < kRounds; ++k) {
        if (n[k] != 0) waiting_by_round_[k].fetch_add(sign * n[k], std::memory_order_relaxed);
    }
}

uint64_t StreamScheduler::WaitingBeforeRound(uint32_t round) const {
    int64_t n = 0;
    for (size_t k = 0; k < std::min<size_t>(round, kRounds); ++k)
        n += waiting_by_round_[k].load(std::memory_order_relaxed);
    return uint64_t(std::max<int64_t>(n, 0));
}

namespace {

/// A number in [0, 1) that looks random and depends on `r`'s path and depth only: which process a
/// ray entering the shared slots goes to. The finalizer of SplitMix64 (Steele, Lea & Flood 2014,
/// "Fast splittable pseudorandom number generators"; constants of Stafford's Mix13).
double PathFraction(const RayRecord& r) {
    uint64_t z = (uint64_t(r.pixel) << 32 | r.sample) + 0x9e3779b97f4a7c15ull * (r.depth + 1u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
}

}  // namespace

uint64_t StreamScheduler::SpreadIntoEverywhere(RayOutbox& out) {
    const int rank = ranks_->rank();
    uint64_t entering = 0;
    std::vector<std::tuple<int, uint32_t, RayRecord>> away;
    auto kept = out.rays.begin();
    for (auto it = out.rays.begin(); it != out.rays.end(); ++it) {
        int dest = rank;
        if (exchange_->Owner(it->first) == kEveryRank) {
            ++entering;
            if (!spread_.empty()) {
                const double u = PathFraction(it->second);
                double below = 0;
                for (size_t d = 0; d < spread_.size(); ++d) {
                    below += spread_[d];
                    dest = int(d);
                    if (u < below) break;
                }
            }
        }
        if (dest == rank) {
            *kept++ = *it;
        } else {
            away.emplace_back(dest, it->first, it->second);
        }
    }
    out.rays.erase(kept, out.rays.end());
    // One send per process and slot, as Flush sends one per slot.
    std::stable_sort(away.begin(), away.end(), [](const auto& a, const auto& b) {
        return std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
    });
    std::vector<RayRecord> group;
    for (size_t i = 0; i < away.size();) {
        const int dest = std::get<0>(away[i]);
        const uint32_t slot = std::get<1>(away[i]);
        group.clear();
        for (; i < away.size() && std::get<0>(away[i]) == dest && std::get<1>(away[i]) == slot; ++i)
            group.push_back(std::get<2>(away[i]));
        exchange_->SendToRank(dest, slot, group);
    }
    return entering;
}

void StreamScheduler::Flush(RayOutbox& out) {
    std::vector<std::pair<uint32_t, RayRecord>>& rays = out.rays;
    std::sort(rays.begin(), rays.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<RayRecord> group;
    for (size_t i = 0; i < rays.size();) {
        size_t j = i;
        group.clear();
        while (j < rays.size() && rays[j].first == rays[i].first) group.push_back(rays[j++].second);
        CountRounds(group, +1);
        exchange_->Send(rays[i].first, group);
        i = j;
    }
    rays.clear();
    const RayCounts& c = out.counts;
    segments_traced_.fetch_add(c.segments_traced, std::memory_order_relaxed);
    shadow_segments_.fetch_add(c.shadow_segments, std::memory_order_relaxed);
    brick_moves_.fetch_add(c.brick_moves, std::memory_order_relaxed);
    rays_.fetch_add(c.rays, std::memory_order_relaxed);
    out.counts = RayCounts();
}

Status StreamScheduler::Drain(RayProcessor& processor, size_t stop_below) {
    return DrainUntil(processor, stop_below, 0);
}

Status StreamScheduler::DrainRoundsBefore(RayProcessor& processor, uint32_t round) {
    if (!count_rounds_ || ranks_ != nullptr) return Drain(processor);
    NAVE_RETURN_IF_ERROR(DrainUntil(processor, 0, round));
    for (uint32_t i = 0; i < queues_.brick_count(); ++i) {
        if (queues_.Waiting(i) > 0) {
            ++rounds_overlapped_;
            break;
        }
    }
    return Status::Ok();
}

Status StreamScheduler::DrainUntil(RayProcessor& processor, size_t stop_below,
                                   uint32_t rounds_before) {
    std::vector<RayRecord> batch;
    std::vector<size_t> waiting(queues_.brick_count());
    for (;;) {
        // Between two batches every ray of this process is in a queue: none of a round before
        // rounds_before there means that none is left.
        if (rounds_before > 0 && WaitingBeforeRound(rounds_before) == 0) break;
        size_t total = 0;
        for (uint32_t i = 0; i < queues_.brick_count(); ++i)
            total += waiting[i] = queues_.Waiting(i);
        if (total <= stop_below) {
            // A complete drain ends when no process has a ray left (one process: now); a partial
            // one when this process has few left, the others' rays still arriving meanwhile.
            if (stop_below > 0 || total > 0) break;
            NAVE_ASSIGN_OR_RETURN(const bool end, exchange_->WaitForRaysOrEnd());
            if (end) break;
            continue;
        }
        if (trace_ != nullptr) {
            trace_->Counter("rays waiting", {{"rays", total}});
            trace_->Counter("memory", {{"resident_bricks", source_.stats().resident_bytes},
                                       {"queues", queues_.MemoryBytes()}});
        }
        NAVE_RETURN_IF_ERROR(SpillIfOverCap(waiting));
        const uint32_t b = picker_ ? picker_(waiting, source_) : pager_->Pick(waiting);
        NAVE_CHECK(b < waiting.size() && waiting[b] > 0)
            << "the brick picker chose brick " << b << " which has no rays waiting";
        const auto batch_start = std::chrono::steady_clock::now();
        // If b must be loaded now, the loader loads the next brick meanwhile: two loads at once
        // while the workers would idle anyway.
        if (!source_.IsResident(b)) pager_->Prefetch(waiting, b, 0);
        NAVE_ASSIGN_OR_RETURN(BrickHandle handle, Acquire(b));
        NAVE_RETURN_IF_ERROR(queues_.Take(b, max_batch_, &batch, queue_spill_.get()).status());
        CountRounds(batch, -1);
        batches_.fetch_add(1, std::memory_order_relaxed);
        waiting[b] -= batch.size();
        pager_->Prefetch(waiting, b,
                         batch.size());  // loads the next brick while this one is traced
        const ResidentBrick& brick = *handle;
        TraceSpan span(trace_, "batch", "scheduler");
        span.AddArg({"brick", b});
        span.AddArg({"rays", batch.size()});
        // Traced: the rays this batch sent to each other brick, which a replay of the render over
        // several processes needs (bench/replay_mpi.py).
        SentPerBrick sent;
        // Rays this batch of a brick's own slot sends to the slots every process holds: the
        // share of this process's work on those that Rebalance credits to the brick.
        const bool held_everywhere = exchange_->Owner(b) == kEveryRank;
        const bool count_into_everywhere = coarse_here_ && !held_everywhere;
        std::atomic<uint64_t> into_everywhere{0};
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, batch.size(), kChunk),
            [&](const tbb::blocked_range<size_t>& range) {
                RayOutbox out;
                processor.ProcessBatch(
                    b, brick,
                    std::span<const RayRecord>(batch).subspan(range.begin(), range.size()), out);
                if (trace_ != nullptr) sent.Count(b, out);
                if (count_into_everywhere) {
                    into_everywhere.fetch_add(SpreadIntoEverywhere(out), std::memory_order_relaxed);
                }
                Flush(out);
            });
        if (trace_ != nullptr) span.AddArg({"sent", sent.Text()});
        handle.Reset();
        const uint64_t batch_us = uint64_t(std::chrono::duration_cast<std::chrono::microseconds>(
                                               std::chrono::steady_clock::now() - batch_start)
                                               .count());
        if (held_everywhere) {
            everywhere_work_us_ += batch_us;
        } else {
            work_us_[b] += batch_us;
            into_everywhere_[source_.BrickOfSlot(b)] += into_everywhere.load();
        }
        pager_->BatchDone();
        NAVE_RETURN_IF_ERROR(exchange_->Progress());
    }
    return Status::Ok();
}

Status StreamScheduler::DrainInWaves(
    RayProcessor& processor, uint64_t count, uint64_t wave_paths, LastWave last,
    const std::function<Status(uint64_t first, uint64_t last)>& generate) {
    for (uint64_t first = 0; first < count; first += wave_paths) {
        NAVE_RETURN_IF_ERROR(generate(first, std::min(count, first + wave_paths)));
        const bool drained = last == LastWave::kDrained && first + wave_paths >= count;
        NAVE_RETURN_IF_ERROR(Drain(processor, drained ? 0 : WaveOverlap()));
    }
    return Status::Ok();
}

Status StreamScheduler::SpillIfOverCap() {
    if (!queue_spill_ || queues_.MemoryBytes() <= queue_memory_) return Status::Ok();
    std::vector<size_t> waiting(queues_.brick_count());
    for (uint32_t i = 0; i < queues_.brick_count(); ++i) waiting[i] = queues_.Waiting(i);
    return SpillIfOverCap(waiting);
}

Status StreamScheduler::SpillIfOverCap(const std::vector<size_t>& waiting) {
    if (!queue_spill_ || queues_.MemoryBytes() <= queue_memory_) return Status::Ok();
    return SpillQueues(waiting);
}

Status StreamScheduler::SpillQueues(const std::vector<size_t>& waiting) {
    // The bricks with the most rays load next: their queues stay. Of the others, the largest
    // queues in memory go first (fewest writes for the bytes freed).
    std::vector<uint32_t> order(waiting.size());
    for (uint32_t b = 0; b < order.size(); ++b) order[b] = b;
    std::sort(order.begin(), order.end(),
              [&](uint32_t a, uint32_t b) { return waiting[a] > waiting[b]; });
    const size_t keep = size_t(std::max(1, pager_->options().loaders)) + 1;
    // Resident bricks' queues too, after the others: when every brick fits (a small model under a
    // large wave) only they hold rays, and the cap must hold all the same.
    std::vector<uint32_t> victims;
    for (size_t i = keep; i < order.size() && waiting[order[i]] > 0; ++i)
        victims.push_back(order[i]);
    std::vector<uint8_t> resident(waiting.size(), 0);
    for (uint32_t b : victims) resident[b] = source_.IsResident(b) ? 1 : 0;
    std::sort(victims.begin(), victims.end(), [&](uint32_t a, uint32_t b) {
        if (resident[a] != resident[b]) return resident[a] < resident[b];
        return queues_.InMemory(a) > queues_.InMemory(b);
    });
    TraceSpan span(trace_, "spill queues", "scheduler");
    for (uint32_t b : victims) {
        if (queues_.MemoryBytes() <= queue_memory_ / 2) break;
        StatusOr<size_t> n = queues_.Spill(b, *queue_spill_);
        if (!n.ok()) {
            return n.status().WithContext(
                "spilling ray queues beyond the memory budget (--temp-dir chooses where)");
        }
        spilled_rays_ += *n;
    }
    return Status::Ok();
}

Status StreamScheduler::Rebalance() {
    if (ranks_ == nullptr) return Status::Ok();
    // One sum over the processes, in integers so that every process sums the same and decides
    // the same: per brick the work of its own slots (a brick's levels go together; each brick's
    // owner measured it) and the rays they sent into the slots every process holds, the work on
    // those slots, and per process all it did.
    const uint32_t bricks = source_.brick_count();
    const int n = ranks_->size();
    std::vector<uint64_t> sums(2 * size_t(bricks) + 1 + size_t(n), 0);
    const std::span<uint64_t> work(sums.data(), bricks), into(sums.data() + bricks, bricks),
        did(sums.data() + 2 * size_t(bricks) + 1, size_t(n));
    uint64_t& shared_work = sums[2 * size_t(bricks)];
    for (uint32_t s = 0; s < work_us_.size(); ++s) work[source_.BrickOfSlot(s)] += work_us_[s];
    for (uint32_t b = 0; b < bricks; ++b) into[b] = into_everywhere_[b];
    shared_work = everywhere_work_us_;
    did[size_t(ranks_->rank())] = std::accumulate(work.begin(), work.end(), everywhere_work_us_);
    std::fill(work_us_.begin(), work_us_.end(), 0);
    std::fill(into_everywhere_.begin(), into_everywhere_.end(), 0);
    everywhere_work_us_ = 0;
    NAVE_RETURN_IF_ERROR(ranks_->SumEverywhere(std::span<uint64_t>(sums)));
    const uint64_t total = std::accumulate(did.begin(), did.end(), uint64_t(0));
    const uint64_t busiest = *std::max_element(did.begin(), did.end());
    if (total == 0 || double(busiest) <= kRebalanceRatio * double(total) / n) return Status::Ok();

    // The work on the shared slots follows the rays into them: each brick is credited with the
    // rays it sent there at the mean work a ray entering them brought.
    const uint64_t entered = std::accumulate(into.begin(), into.end(), uint64_t(0));
    const double per_entry = entered > 0 ? double(shared_work) / double(entered) : 0.0;
    std::vector<uint64_t> weight(bricks);
    for (uint32_t b = 0; b < bricks; ++b)
        weight[b] = work[b] + uint64_t(per_entry * double(into[b]));
    std::vector<int> next = BrickOwnersByWork(source_, n, weight);
    std::vector<double> made(size_t(n), 0.0), shared(size_t(n), 0.0);
    for (uint32_t b = 0; b < bricks; ++b) {
        const size_t r = size_t(next[source_.SlotOf(b, 0)]);
        made[r] += double(weight[b]);
        shared[r] += per_entry * double(into[b]);
    }
    // Processes above the mean hand rays entering the shared slots to those below it.
    const std::vector<std::vector<double>> spread = SpreadOfSharedWork(made, shared);
    std::vector<double> after(size_t(n), 0.0);
    for (size_t r = 0; r < size_t(n); ++r) {
        after[r] += made[r] - shared[r];
        for (size_t d = 0; d < size_t(n); ++d) after[d] += shared[r] * spread[r][d];
    }
    const double busiest_after = *std::max_element(after.begin(), after.end());
    if (busiest_after >= double(busiest)) return Status::Ok();
    spread_ = spread[size_t(ranks_->rank())];
    brick_owners_ = std::move(next);
    std::vector<int> owners = SlotOwners();
    for (uint32_t s = 0; s < owners.size(); ++s) {
        if (exchange_->Owns(s) && !TracedBy(owners[s], ranks_->rank())) pager_->Evict(s);
    }
    NAVE_RETURN_IF_ERROR(exchange_->SetOwners(std::move(owners)));
    log::Debug(
        "ranks: bricks re-balanced by measured work: the busiest rank had {:.2f}x the mean, "
        "now {:.2f}x",
        double(busiest) * n / double(total), double(busiest_after) * n / double(total));
    ++rebalances_;
    return Status::Ok();
}

size_t StreamScheduler::WaveOverlap() const {
    if (pager_->options().in_core()) return 0;
    return size_t(pager_->options().wave_overlap * double(wave_paths_));
}

Status StreamScheduler::SumStatsOverRanks(StreamStats* stats) const {
    if (ranks_ == nullptr) return Status::Ok();
    uint64_t counts[] = {stats->rays,        stats->segments_traced, stats->shadow_segments,
                         stats->brick_moves, stats->batches,         stats->bytes_read,
                         stats->spilled_rays};
    NAVE_RETURN_IF_ERROR(ranks_->SumEverywhere(counts));
    stats->rays = counts[0];
    stats->segments_traced = counts[1];
    stats->shadow_segments = counts[2];
    stats->brick_moves = counts[3];
    stats->batches = counts[4];
    stats->bytes_read = counts[5];
    stats->spilled_rays = counts[6];
    stats->ranks = ranks_->size();
    stats->rebalances = rebalances_;
    NAVE_ASSIGN_OR_RETURN(stats->exchange, exchange_->TotalCounts());
    return Status::Ok();
}

void StreamScheduler::FillStats(const BrickSourceStats& before, StreamStats* stats) const {
    const BrickSourceStats after = source_.stats();
    stats->segments_traced = segments_traced_.load();
    stats->shadow_segments = shadow_segments_.load();
    stats->brick_moves = brick_moves_.load();
    stats->rays = rays_.load();
    stats->batches = batches_.load();
    stats->rounds_overlapped = rounds_overlapped_;
    stats->peak_queue_bytes =
        std::max<uint64_t>(stats->peak_queue_bytes, queues_.PeakMemoryBytes());
    stats->bytes_read = after.bytes_read - before.bytes_read;
    PagerStats& residency = stats->residency;
    residency = pager_->stats();
    if (pager_->options().in_core()) residency.brick_budget_bytes = 0;
    // The source counts every load, the pager's and any before it.
    residency.loads = after.loads - before.loads;
    if (queue_spill_) {
        const store::SpillStats q = queue_spill_->stats();
        stats->spilled_rays = spilled_rays_;
        stats->spill_bytes_written = q.stored_bytes_written;
        stats->spill_peak_disk_bytes = q.peak_stored_bytes;
    }
    if (brick_cache_) {
        const BrickCacheStats c = brick_cache_->stats();
        stats->brick_cache_written = c.bricks_written;
        stats->brick_cache_reads = c.reads;
        stats->brick_cache_disk_bytes = c.disk_bytes;
        stats->brick_cache_mesh_bytes = c.mesh_bytes;
    }
}

}  // namespace nave::render
