#pragma once
// Memory sizes: parsing user budgets ("8G", "512MiB"), printing them, and measuring the process.

#include <cstdint>
#include <string>
#include <string_view>

#include "core/status.h"

namespace nave {

/// Parses "123", "64K", "512M", "1.5G", "2GiB", "300MB" (K/M/G/T are powers of 1024, as in `--memory 8G`).
/// Errors name the text and the accepted forms.
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

}  // namespace nave
