#pragma once
// Adding to a floating-point atomic from many threads without a lock (std::atomic<float>::fetch_add
// is C++20 but not in every standard library nave builds with).

#include <atomic>

namespace nave {

/// a += v, atomically (compare-and-swap loop, relaxed order: sums, not synchronisation).
template <typename T>
void AtomicAdd(std::atomic<T>& a, T v) {
    T old = a.load(std::memory_order_relaxed);
    while (!a.compare_exchange_weak(old, old + v, std::memory_order_relaxed)) {
    }
}

}  // namespace nave
