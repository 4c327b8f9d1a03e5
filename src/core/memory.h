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
    /// `limit_bytes` 0: no limit from the user. The allocator's free pages then still go back once
    /// they would be a third of the process (kSlackShare past what it held after its last return,
    /// plus kSlackBytes): freed and reused in sizes that do not fit each other, they otherwise pile
    /// up for as long as the process runs (a 480x320 path-traced abbey held 536 MiB after 30 s, 827
    /// MiB after 60 s and 1.32 GiB after 120 s, for 26 MiB allocated).
    explicit ResidentSizeGuard(uint64_t limit_bytes) : limit_bytes_(limit_bytes) {}
    /// Before allocating about `bytes`: when the resident size plus `bytes` passes the limit (or,
    /// without one, the slack above the last return), gives the allocator's free pages back
    /// (ReturnFreeMemory). Returns whether it did.
    bool MakeRoom(uint64_t bytes);

    /// Without a limit: how much of the resident size after the last return may be added before the
    /// next, as a share of it and in bytes.
    static constexpr double kSlackShare = 0.5;
    static constexpr uint64_t kSlackBytes = uint64_t(128) << 20;
    /// How many times MakeRoom gave pages back.
    uint64_t returns() const { return returns_.load(std::memory_order_relaxed); }

  private:
    const uint64_t limit_bytes_;
    std::mutex mutex_;  // one return at a time; the others then see the smaller resident size
    std::atomic<uint64_t> returns_{0};
    /// Without a limit: the resident size after the last return (0: none yet, the first check
    /// returns pages and sets it).
    std::atomic<uint64_t> after_return_bytes_{0};
};

}  // namespace nave
