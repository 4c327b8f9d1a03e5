#pragma once
// Per-brick queues of waiting rays. Every ray in flight (camera path, shadow ray, photon) waits in the queue
// of the brick its next segment lies in. Queues hold ray records only: nothing here touches a brick's
// geometry, so a queue may grow for a brick that is not resident (the pager decides when to load it).

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

    void Push(uint32_t brick, const R& record) {
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        q.records.push_back(record);
        q.size.store(q.records.size(), std::memory_order_relaxed);
    }
    void Push(uint32_t brick, const R* records, size_t count) {
        if (count == 0) return;
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        q.records.insert(q.records.end(), records, records + count);
        q.size.store(q.records.size(), std::memory_order_relaxed);
    }
    /// Moves up to `max_count` records of `brick` into `out` (cleared first), the most recent first so the
    /// queue's storage is reused; returns how many.
    size_t Take(uint32_t brick, size_t max_count, std::vector<R>* out) {
        out->clear();
        Queue& q = *queues_[brick];
        std::lock_guard<std::mutex> lock(q.mutex);
        size_t n = std::min(max_count, q.records.size());
        out->assign(q.records.end() - std::ptrdiff_t(n), q.records.end());
        q.records.resize(q.records.size() - n);
        if (q.records.empty()) q.records.shrink_to_fit();
        q.size.store(q.records.size(), std::memory_order_relaxed);
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
    struct Queue {
        std::mutex mutex;
        std::vector<R> records;
        std::atomic<size_t> size{0};
    };
    std::vector<std::unique_ptr<Queue>> queues_;
};

}  // namespace nave::render
