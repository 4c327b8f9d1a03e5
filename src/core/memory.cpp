#include "src/core/memory.h"

#include <fcntl.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

// jemalloc's control interface, present when the executable links jemalloc (`nave` does, the tests
// do not): a weak reference is null otherwise.
extern "C" int mallctl(const char* name, void* oldp, size_t* oldlenp, void* newp, size_t newlen)
    __attribute__((weak));

namespace nave {

StatusOr<uint64_t> ParseByteSize(std::string_view text) {
    auto bad = [&] {
        return InvalidArgumentError(
            "'{}' is not a size: expected a number with an optional unit, "
            "as in 512M, 1.5G, 2GiB or 1048576",
            text);
    };
    size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.'))
        ++i;
    if (i == 0) return bad();
    double number = 0;
    auto [ptr, ec] = std::from_chars(text.data(), text.data() + i, number);
    if (ec != std::errc() || ptr != text.data() + i || !std::isfinite(number) || number < 0)
        return bad();
    std::string unit;
    for (char c : text.substr(i)) unit += char(std::toupper(static_cast<unsigned char>(c)));
    double scale = 1;
    if (unit.empty() || unit == "B")
        scale = 1;
    else if (unit == "K" || unit == "KB" || unit == "KIB")
        scale = 1024.0;
    else if (unit == "M" || unit == "MB" || unit == "MIB")
        scale = 1024.0 * 1024;
    else if (unit == "G" || unit == "GB" || unit == "GIB")
        scale = 1024.0 * 1024 * 1024;
    else if (unit == "T" || unit == "TB" || unit == "TIB")
        scale = 1024.0 * 1024 * 1024 * 1024;
    else
        return bad();
    double bytes = number * scale;
    if (bytes > 9.0e18) return bad();
    return static_cast<uint64_t>(bytes);
}

std::string FormatBytes(uint64_t bytes) {
    const double b = double(bytes);
    if (b >= 1024.0 * 1024 * 1024) return fmt::format("{:.2f} GiB", b / (1024.0 * 1024 * 1024));
    if (b >= 1024.0 * 1024) return fmt::format("{:.1f} MiB", b / (1024.0 * 1024));
    if (b >= 1024.0) return fmt::format("{:.1f} KiB", b / 1024.0);
    return fmt::format("{} B", bytes);
}

namespace {
uint64_t ReadProcStatusKiB(const char* key) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string prefix = std::string(key) + ":";
    while (std::getline(in, line)) {
        if (line.rfind(prefix, 0) == 0) return std::stoull(line.substr(prefix.size())) * 1024;
    }
    return 0;
}
}  // namespace

uint64_t PeakRssBytes() { return ReadProcStatusKiB("VmHWM"); }
uint64_t CurrentRssBytes() {
    // /proc/self/statm's second field, resident pages: one read, cheap enough to ask before every
    // brick load (ResidentSizeGuard).
    const int fd = open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
    if (fd < 0) return 0;
    char text[128];
    const ssize_t n = read(fd, text, sizeof(text) - 1);
    close(fd);
    if (n <= 0) return 0;
    text[n] = 0;
    unsigned long long size = 0, resident = 0;
    if (std::sscanf(text, "%llu %llu", &size, &resident) != 2) return 0;
    return uint64_t(resident) * uint64_t(sysconf(_SC_PAGE_SIZE));
}

uint64_t PhysicalMemoryBytes() {
    long pages = sysconf(_SC_PHYS_PAGES);
    long page_size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page_size > 0 ? uint64_t(pages) * uint64_t(page_size) : 0;
}

void ReturnFreeMemory() {
    if (mallctl != nullptr) {
        // "arena.4096.purge": 4096 is MALLCTL_ARENAS_ALL, every arena.
        mallctl("arena.4096.purge", nullptr, nullptr, nullptr, 0);
        return;
    }
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

bool ResidentSizeGuard::MakeRoom(uint64_t bytes) {
    if (limit_bytes_ == 0) {
        // No budget: only the free pages that piled up go back, measured against what the process
        // held right after the last return (its live memory then, and its allocations since).
        const uint64_t base = after_return_bytes_.load(std::memory_order_relaxed);
        const uint64_t allowed = base + uint64_t(double(base) * kSlackShare) + kSlackBytes;
        if (base != 0 && CurrentRssBytes() + bytes <= allowed) return false;
        std::lock_guard<std::mutex> lock(mutex_);
        if (after_return_bytes_.load(std::memory_order_relaxed) != base) return false;  // done
        ReturnFreeMemory();
        returns_.fetch_add(1, std::memory_order_relaxed);
        after_return_bytes_.store(CurrentRssBytes(), std::memory_order_relaxed);
        return true;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (CurrentRssBytes() + bytes <= limit_bytes_) return false;
    ReturnFreeMemory();
    returns_.fetch_add(1, std::memory_order_relaxed);
    return true;
}

std::string AllocatorName() {
    const char* version = nullptr;
    size_t length = sizeof(version);
    if (mallctl != nullptr && mallctl("version", &version, &length, nullptr, 0) == 0 &&
        version != nullptr) {
        return std::string("jemalloc ") + version;
    }
    return "glibc malloc";
}

}  // namespace nave
