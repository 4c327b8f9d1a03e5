#pragma once
// Memory sizes: parsing user budgets ("8G", "512MiB"), printing them, and measuring the process.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave {

/// Parses "123", "64K", "512M", "1.5G", "2GiB", "300MB" (K/M/G/T are powers of 1024, as in
/// `--memory 8G`). Errors name the text and the accepted forms.
StatusOr<uint64_t> ParseByteSize(std::string_view text);
/// "1.50 GiB", "512.0 MiB", "12 B".
std::string FormatBytes(uint64_t bytes);
/// Peak resident set size of this process so far (VmHWM), in bytes; 0 if unknown.
uint64_t PeakRssBytes();
/// Current resident set size (VmRSS), in bytes; 0 if unknown.
uint64_t CurrentRssBytes();
/// Physical memory of the machine, in bytes.
uint64_t PhysicalMemoryBytes();
/// Gives the pages the allocator holds free back to the system now (jemalloc's purge, in the `nave`
/// executable; glibc's malloc_trim elsewhere), e.g. before a phase that needs memory the last one
/// freed.
void ReturnFreeMemory();
/// The allocator serving malloc in this process: "jemalloc 5.3.0-..." or "glibc malloc".
std::string AllocatorName();

/// Holds the process's resident size under a limit (the user's --memory) by giving the allocator's
/// free pages back when an allocation would pass it. Pages a program frees stay with the allocator,
/// where the next allocation of that size reuses them without a page fault; returning them at once
/// costs a fault per page on every reuse, keeping them all lets the process grow past its budget.
/// This returns them only when memory is short. Thread-safe.
class ResidentSizeGuard {
  public:
    /// `limit_bytes` 0: no limit (MakeRoom never returns pages).
    explicit ResidentSizeGuard(uint64_t limit_bytes) : limit_bytes_(limit_bytes) {}
    /// Before allocating about `bytes`: when the resident size plus `bytes` passes the limit, gives
    /// the allocator's free pages back (ReturnFreeMemory). Returns whether it did.
    bool MakeRoom(uint64_t bytes);
    /// How many times MakeRoom gave pages back.
    uint64_t returns() const { return returns_.load(std::memory_order_relaxed); }

  private:
    const uint64_t limit_bytes_;
    std::mutex mutex_;  // one return at a time; the others then see the smaller resident size
    std::atomic<uint64_t> returns_{0};
};

}  // namespace nave
