#pragma once
// Per-brick queues of waiting rays. Every ray in flight (camera path, shadow ray, photon) waits in the queue
// of the brick its next segment lies in. Queues hold ray records only: nothing here touches a brick's
// geometry, so a queue may grow for a brick that is not resident (the pager decides when to load it).
// Records are stored in blocks of bounded size rather than one growing vector: a vector doubling its
// capacity holds up to 2x its records, 3x while it reallocates, and keeps that after a partial take; under
// the pager, whose order leaves many queues long at once, that slack measured 3.2x the records (525 MiB of
// capacity for 165 MiB of rays). Blocks bound the slack to one partly filled block per queue.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>


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
                // Blocks double from kFirstBlock to kMaxBlock records: short queues (most bricks of a large
                // model) stay small, long ones pay one partly filled block at most.
                size_t capacity = q.blocks.empty() ? kFirstBlock : std::min(kMaxBlock, 2 * q.blocks.back().capacity());
                q.blocks.emplace_back();
                q.blocks.back().reserve(capacity);
            }
            std::vector<R>& block = q.blocks.back();
            size_t n = std::min(count, block.capacity() - block.size());
            block.insert(block.end(), records, records + n);
            records += n;
            count -= n;
            q.count += n;
        }
        q.size.store(q.count, std::memory_order_relaxed);
    }
    /// Moves up to `max_count` records of `brick` into `out` (cleared first): the most recent ones, in the
    /// order they were pushed, so that emptied blocks are freed at once; returns how many.
    size_t Take(uint32_t brick, size_t max_count, std::vector<R>* out) {
        out->clear();
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        size_t n = std::min(max_count, q.count);
        out->resize(n);
        size_t pos = n;
        while (pos > 0) {
            std::vector<R>& block = q.blocks.back();
            size_t k = std::min(pos, block.size());
            std::copy(block.end() - std::ptrdiff_t(k), block.end(), out->begin() + std::ptrdiff_t(pos - k));
            block.resize(block.size() - k);
            pos -= k;
            if (block.empty()) q.blocks.pop_back();
        }
        q.count -= n;
        q.size.store(q.count, std::memory_order_relaxed);
        return n;
    }
    /// Rays waiting in `brick` (a snapshot).
    size_t Waiting(uint32_t brick) const { return queues_[brick]->size.load(std::memory_order_relaxed); }
    size_t TotalWaiting() const {
        size_t n = 0;
        for (const auto& q : queues_) n += q->size.load(std::memory_order_relaxed);
        return n;
    }
    /// Bytes held by the queues (for statistics and budgets).
    size_t MemoryBytes() const {
        size_t n = 0;
        for (const auto& q : queues_) n += q->size.load(std::memory_order_relaxed) * sizeof(R);
        return n;
    }

  private:
    static constexpr size_t kFirstBlock = 64;
    static constexpr size_t kMaxBlock = 4096;
    struct Queue {
        std::mutex mutex;
        std::vector<std::vector<R>> blocks;  // only the last may have room left
        size_t count = 0;
        std::atomic<size_t> size{0};
    };
    std::vector<std::unique_ptr<Queue>> queues_;
};

}  // namespace nave::render
