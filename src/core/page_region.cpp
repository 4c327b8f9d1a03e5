#include "src/core/page_region.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace nave {
namespace {

constexpr size_t kHugePage = size_t(2) << 20;

size_t PageSize() {
    static const size_t size = size_t(::sysconf(_SC_PAGESIZE));
    return size;
}

size_t RoundUp(size_t bytes, size_t to) { return (bytes + to - 1) / to * to; }

}  // namespace

PageRegion::~PageRegion() { Unmap(); }

PageRegion::PageRegion(PageRegion&& o) noexcept
    : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)) {}

PageRegion& PageRegion::operator=(PageRegion&& o) noexcept {
    if (this != &o) {
        Unmap();
        data_ = std::exchange(o.data_, nullptr);
        size_ = std::exchange(o.size_, 0);
    }
    return *this;
}

void PageRegion::Unmap() {
    if (data_ != nullptr) ::munmap(data_, size_);
    data_ = nullptr;
    size_ = 0;
}

size_t PageRegion::MappedBytes(size_t bytes) { return RoundUp(bytes, PageSize()); }

StatusOr<PageRegion> PageRegion::Map(size_t bytes) {
    const size_t size = MappedBytes(bytes);
    if (size == 0) return PageRegion();
    // A huge-page-aligned start needs up to one huge page more of address space; the slack on
    // either side is unmapped at once (it was never touched, so it never held memory).
    const bool huge = size >= kHugePage;
    const size_t reserve = huge ? size + kHugePage : size;
    void* p = ::mmap(nullptr, reserve, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) {
        const int err = errno;
        return ResourceExhaustedError("cannot map {} bytes of memory: {}", size,
                                      std::strerror(err));
    }
    auto* base = static_cast<std::byte*>(p);
    if (!huge) return PageRegion(base, size);
    std::byte* start =
        reinterpret_cast<std::byte*>(RoundUp(reinterpret_cast<uintptr_t>(base), kHugePage));
    if (start > base) ::munmap(base, size_t(start - base));
    std::byte* end = start + size;
    if (base + reserve > end) ::munmap(end, size_t(base + reserve - end));
#if defined(MADV_HUGEPAGE)
    ::madvise(start, size,
              MADV_HUGEPAGE);  // advice only: without huge pages the region still works
#endif
    return PageRegion(start, size);
}

}  // namespace nave
