#pragma once
// Per-brick queues of waiting rays. Every ray in flight (camera path, shadow ray, photon) waits in
// the queue of the brick its next segment lies in. Queues hold ray records only: nothing here
// touches a brick's geometry, so a queue may grow for a brick that is not resident (the pager
// decides when to load it). Records are stored in blocks of bounded size rather than one growing
// vector: a vector doubling its capacity holds up to 2x its records, 3x while it reallocates, and
// keeps that after a partial take; under the pager, whose order leaves many queues long at once,
// that slack measured 3.2x the records (525 MiB of capacity for 165 MiB of rays). Blocks bound the
// slack to one partly filled block per queue. Under a memory budget, the full blocks of a queue may
// be spilled to disk (LZ4, SpillFile) and are read back when the queue is taken: queues can then
// outgrow RAM while their bricks wait to be loaded.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "src/core/status.h"
#include "store/spill_file.h"

namespace nave::render {

/// Queues of records of type R, one per brick. Push and Take are thread-safe.
template <typename R>
class BrickQueues {
  public:
    explicit BrickQueues(uint32_t brick_count) : queues_(brick_count) {
        for (auto& q : queues_) q = std::make_unique<Queue>();
    }

    uint32_t brick_count() const { return uint32_t(queues_.size()); }

    void Push(uint32_t brick, const R& record) { Push(brick, &record, 1); }
    void Push(uint32_t brick, const R* records, size_t count) {
        if (count == 0) return;
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        while (count > 0) {
            if (q.blocks.empty() || q.blocks.back().size() == q.blocks.back().capacity()) {
                // Blocks double from kFirstBlock to kMaxBlock records: short queues (most bricks of
                // a large model) stay small, long ones pay one partly filled block at most.
                size_t capacity = q.blocks.empty()
                                      ? kFirstBlock
                                      : std::min(kMaxBlock, 2 * q.blocks.back().capacity());
                q.blocks.emplace_back();
                q.blocks.back().reserve(capacity);
            }
            std::vector<R>& block = q.blocks.back();
            size_t n = std::min(count, block.capacity() - block.size());
            block.insert(block.end(), records, records + n);
            records += n;
            count -= n;
            q.count += n;
            q.in_memory += n;
        }
        Publish(q);
    }
    /// Moves up to `max_count` records of `brick` into `out` (cleared first): the most recent ones
    /// in memory, in the order they were pushed, so that emptied blocks are freed at once, then
    /// spilled blocks read back from `file` (newest first); returns how many. Errors: a spilled
    /// block that cannot be read back (names the spill directory). Not to be called while records
    /// are pushed to the same brick.
    StatusOr<size_t> Take(uint32_t brick, size_t max_count, std::vector<R>* out,
                          store::SpillFile* file = nullptr) {
        out->clear();
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        size_t n = std::min(max_count, q.count);
        out->resize(n);
        size_t pos = n;
        while (pos > 0 && !q.blocks.empty()) {
            std::vector<R>& block = q.blocks.back();
            size_t k = std::min(pos, block.size());
            std::copy(block.end() - std::ptrdiff_t(k), block.end(),
                      out->begin() + std::ptrdiff_t(pos - k));
            block.resize(block.size() - k);
            pos -= k;
            q.in_memory -= k;
            if (block.empty()) q.blocks.pop_back();
        }
        while (pos > 0) {
            Spilled& s = q.spilled.back();
            if (file == nullptr)
                return InternalError("brick {}: spilled rays but no spill file to read", brick);
            std::vector<R> block(s.count);
            Status read = file->Read(s.extent, block.data());
            if (!read.ok())
                return read.WithContext(fmt::format("reading back the rays of brick {}", brick));
            // What was read back is no longer on disk: the remainder (if the take ends inside the
            // block) goes back to memory.
            file->Release(s.extent);
            q.spilled.pop_back();
            size_t k = std::min(pos, block.size());
            std::copy(block.end() - std::ptrdiff_t(k), block.end(),
                      out->begin() + std::ptrdiff_t(pos - k));
            pos -= k;
            block.resize(block.size() - k);
            if (!block.empty()) {
                block.shrink_to_fit();  // full, as Spill expects of every block but the last
                q.in_memory += block.size();
                q.blocks.insert(q.blocks.begin(), std::move(block));
            }
        }
        q.count -= n;
        Publish(q);
        return n;
    }
    /// Writes the full blocks of `brick`'s queue to `file` and frees them (the last, partly filled
    /// block stays); returns the records spilled. Errors: a failed write (a full disk), naming the
    /// spill directory.
    StatusOr<size_t> Spill(uint32_t brick, store::SpillFile& file) {
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        size_t spilled = 0;
        // Oldest blocks first: Take reads the newest records first, so these wait longest.
        size_t full = 0;
        while (full < q.blocks.size() && q.blocks[full].size() == q.blocks[full].capacity() &&
               full + 1 < q.blocks.size()) {
            ++full;
        }
        for (size_t i = 0; i < full; ++i) {
            std::vector<R>& block = q.blocks[i];
            StatusOr<store::SpillExtent> extent =
                file.Write(block.data(), block.size() * sizeof(R));
            if (!extent.ok()) {
                q.blocks.erase(q.blocks.begin(), q.blocks.begin() + std::ptrdiff_t(i));
                Publish(q);
                return extent.status();
            }
            q.spilled.push_back({std::move(extent).value(), block.size()});
            q.in_memory -= block.size();
            spilled += block.size();
        }
        q.blocks.erase(q.blocks.begin(), q.blocks.begin() + std::ptrdiff_t(full));
        Publish(q);
        return spilled;
    }
    /// Records of `brick` held in memory (not spilled; a snapshot).
    size_t InMemory(uint32_t brick) const {
        return queues_[brick]->memory_size.load(std::memory_order_relaxed);
    }
    /// Rays waiting in `brick` (a snapshot).
    size_t Waiting(uint32_t brick) const {
        return queues_[brick]->size.load(std::memory_order_relaxed);
    }
    size_t TotalWaiting() const {
        size_t n = 0;
        for (const auto& q : queues_) n += q->size.load(std::memory_order_relaxed);
        return n;
    }
    /// Bytes the queues hold in memory (for statistics and budgets); spilled records are not
    /// counted.
    size_t MemoryBytes() const { return in_memory_.load(std::memory_order_relaxed) * sizeof(R); }
    /// The most MemoryBytes has been, at any moment.
    size_t PeakMemoryBytes() const {
        return peak_in_memory_.load(std::memory_order_relaxed) * sizeof(R);
    }

  private:
    static constexpr size_t kFirstBlock = 64;
    static constexpr size_t kMaxBlock = 4096;
    struct Spilled {
        store::SpillExtent extent;
        size_t count;
    };
    struct Queue {
        std::mutex mutex;
        std::vector<std::vector<R>> blocks;  // only the last may have room left
        std::vector<Spilled> spilled;        // older than every block in memory, oldest first
        size_t count = 0;                    // records in memory and spilled
        size_t in_memory = 0;
        std::atomic<size_t> size{0};         // count, for other threads
        std::atomic<size_t> memory_size{0};  // in_memory, for other threads
    };
    std::vector<std::unique_ptr<Queue>> queues_;
    std::atomic<size_t> in_memory_{0};       // records in memory over all queues
    std::atomic<size_t> peak_in_memory_{0};  // the most in_memory_ has been

    /// Publishes q's counts to other threads (under q.mutex) and keeps the totals over all queues.
    void Publish(Queue& q) {
        q.size.store(q.count, std::memory_order_relaxed);
        const size_t before = q.memory_size.exchange(q.in_memory, std::memory_order_relaxed);
        if (q.in_memory >= before) {
            const size_t now =
                in_memory_.fetch_add(q.in_memory - before, std::memory_order_relaxed) +
                (q.in_memory - before);
            size_t peak = peak_in_memory_.load(std::memory_order_relaxed);
            while (now > peak &&
                   !peak_in_memory_.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
            }
        } else {
            in_memory_.fetch_sub(before - q.in_memory, std::memory_order_relaxed);
        }
    }
};

}  // namespace nave::render
