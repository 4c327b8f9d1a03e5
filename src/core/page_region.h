#pragma once
// Memory straight from the operating system, returned whole when freed. What a long-running process
// allocates and frees in large pieces of many sizes (a renderer's bricks under a memory budget)
// leaves holes in malloc's heap that the next piece does not fit: at a billion triangles the heap
// grew to twice the bytes it held. A region is its own mapping, so freeing it gives every page
// back.

#include <cstddef>
#include <cstdint>

#include "src/core/status.h"

namespace nave {

/// One anonymous private mapping, zero-filled, read-write. Move-only; unmapped on destruction.
class PageRegion {
  public:
    PageRegion() = default;
    ~PageRegion();
    PageRegion(PageRegion&& o) noexcept;
    PageRegion& operator=(PageRegion&& o) noexcept;
    PageRegion(const PageRegion&) = delete;
    PageRegion& operator=(const PageRegion&) = delete;

    /// Maps `bytes` (rounded up to whole pages; 0 gives an empty region). Regions of at least a
    /// huge page start on a huge-page boundary and ask for transparent huge pages: a 4 KiB page
    /// costs a fault on first touch (12 us on virtual machines), a 2 MiB page one fault for 512
    /// times the memory. Errors (no address space, a mapping limit) say how many bytes were asked.
    static StatusOr<PageRegion> Map(size_t bytes);
    /// The bytes a region of `bytes` holds once touched: `bytes` rounded up to whole pages.
    static size_t MappedBytes(size_t bytes);

    std::byte* data() const { return data_; }
    size_t size() const { return size_; }

  private:
    PageRegion(std::byte* data, size_t size) : data_(data), size_(size) {}
    void Unmap();
    std::byte* data_ = nullptr;
    size_t size_ = 0;
};

}  // namespace nave
