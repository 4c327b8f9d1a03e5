#include "render/stream_scheduler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "core/check.h"
#include "core/trace.h"
#include "render/brick_walk.h"

namespace nave::render {
namespace {

/// Rays taken from a queue per scheduler step, and rays per task within it.
constexpr size_t kMaxBatch = 1u << 18;
constexpr size_t kChunk = 256;

}  // namespace

StreamScheduler::StreamScheduler(BrickSource& source, BrickPicker picker, uint64_t wave_paths)
    : source_(source),
      tree_(source.tree()),
      custom_picker_(bool(picker)),
      picker_(picker ? std::move(picker) : BrickPicker(PickFullestBrick)),
      wave_paths_(wave_paths),
      queues_(source.brick_count()) {}

Status StreamScheduler::EnablePaging(const PagerOptions& options) {
    NAVE_RETURN_IF_ERROR(source_.SetBvhSettings(options.bvh));
    source_.SetTrace(options.trace);
    trace_ = options.trace;
    if (trace_ != nullptr) trace_->NameThread("scheduler");
    NAVE_ASSIGN_OR_RETURN(
        pager_, Pager::Create(source_, options, [this](uint32_t b) { return queues_.Waiting(b); }));
    return Status::Ok();
}

StatusOr<BrickHandle> StreamScheduler::Acquire(uint32_t brick) {
    if (pager_) return pager_->Acquire(brick);
    const auto start = std::chrono::steady_clock::now();
    StatusOr<BrickHandle> h = source_.Acquire(brick);
    stall_seconds_ +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return h;
}

uint32_t StreamScheduler::Route(RayRecord& r, float from_t, uint32_t current) const {
    BrickSegment s = NextBrick(tree_, r.origin, r.dir, from_t, r.t_max, current);
    r.t_enter = s.t_enter;
    r.t_exit = s.t_exit;
    return s.brick;
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
        exchange_.Send(rays[i].first, group);
        i = j;
    }
    rays.clear();
    const RayCounts& c = out.counts;
    segments_.fetch_add(c.segments, std::memory_order_relaxed);
    shadow_segments_.fetch_add(c.shadow_segments, std::memory_order_relaxed);
    moves_.fetch_add(c.moves, std::memory_order_relaxed);
    rays_.fetch_add(c.rays, std::memory_order_relaxed);
    out.counts = RayCounts();
}

Status StreamScheduler::Drain(RayProcessor& processor, size_t stop_below) {
    std::vector<RayRecord> batch;
    std::vector<size_t> waiting(queues_.brick_count());
    for (;;) {
        size_t total = 0;
        for (uint32_t i = 0; i < queues_.brick_count(); ++i)
            total += waiting[i] = queues_.Waiting(i);
        if (total <= stop_below) break;
        if (trace_ != nullptr) {
            trace_->Counter("rays waiting", {{"rays", total}});
            trace_->Counter("memory", {{"resident_bricks", source_.stats().resident_bytes},
                                       {"queues", queues_.MemoryBytes()}});
        }
        const uint32_t b =
            pager_ && !custom_picker_ ? pager_->Pick(waiting) : picker_(waiting, source_);
        NAVE_CHECK(b < waiting.size() && waiting[b] > 0)
            << "the brick picker chose brick " << b << " which has no rays waiting";
        peak_queue_bytes_ = std::max<uint64_t>(peak_queue_bytes_, queues_.MemoryBytes());
        // If b must be loaded now, the loader loads the next brick meanwhile: two loads at once
        // while the workers would idle anyway.
        if (pager_ && !source_.IsResident(b)) pager_->Prefetch(waiting, b, 0);
        NAVE_ASSIGN_OR_RETURN(BrickHandle handle, Acquire(b));
        queues_.Take(b, kMaxBatch, &batch);
        batches_.fetch_add(1, std::memory_order_relaxed);
        if (pager_) {
            waiting[b] -= batch.size();
            pager_->Prefetch(waiting, b,
                             batch.size());  // loads the next brick while this batch is traced
        }
        const ResidentBrick& brick = *handle;
        TraceSpan span(trace_, "batch", "scheduler");
        span.AddArg({"brick", b});
        span.AddArg({"rays", batch.size()});
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, batch.size(), kChunk),
            [&](const tbb::blocked_range<size_t>& range) {
                RayOutbox out;
                processor.ProcessBatch(
                    b, brick,
                    std::span<const RayRecord>(batch).subspan(range.begin(), range.size()), out);
                Flush(out);
            });
        if (pager_) {
            handle.Reset();
            pager_->BatchDone();
        }
    }
    return Status::Ok();
}

size_t StreamScheduler::WaveOverlap() const {
    if (!pager_ || pager_->options().in_core()) return 0;
    return size_t(pager_->options().wave_overlap * double(wave_paths_));
}

void StreamScheduler::FillStats(const BrickSourceStats& before, RenderStats* stats) const {
    const BrickSourceStats after = source_.stats();
    stats->segments_traced = segments_.load();
    stats->shadow_segments = shadow_segments_.load();
    stats->brick_moves = moves_.load();
    stats->rays = rays_.load();
    stats->batches = batches_.load();
    stats->peak_queue_bytes = std::max(stats->peak_queue_bytes, peak_queue_bytes_);
    stats->brick_loads = after.loads - before.loads;
    stats->bytes_read = after.bytes_read - before.bytes_read;
    stats->brick_acquires = after.acquires - before.acquires;
    if (pager_) {
        const PagerStats p = pager_->stats();
        stats->brick_budget_bytes = pager_->options().in_core() ? 0 : p.brick_budget_bytes;
        stats->peak_brick_bytes = p.peak_resident_bytes;
        stats->brick_evictions = p.evictions;
        stats->brick_reloads = p.reloads;
        stats->prefetch_loads = p.prefetch_loads;
        stats->prefetch_hits = p.prefetch_hits;
        stats->brick_acquires = p.acquires;
        stats->stall_seconds = p.stall_seconds;
    } else {
        stats->peak_brick_bytes = after.peak_resident_bytes;
        stats->brick_evictions = after.evictions - before.evictions;
        stats->stall_seconds = stall_seconds_;
        stats->prefetch_hits =
            stats->brick_acquires - std::min(stats->brick_acquires, stats->brick_loads);
    }
}

}  // namespace nave::render
