#pragma once
// Decoded brick meshes kept on disk while the brick is out of memory (docs/pager.md, "Reloads"):
// under a budget a brick is loaded several times, and Draco decoding is most of a load's work. The
// first load writes the decoded mesh to a spill file (LZ4, checksummed); later loads read it back
// at disk or page-cache speed and only rebuild the BVH. The cache holds at most its limit on disk;
// past it, or after a write error (a full disk), loads decode from the store as without a cache.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "src/core/status.h"
#include "src/render/bricks/resident_mesh.h"
#include "store/brick_mesh.h"
#include "store/spill_file.h"

namespace nave::render {

/// What the brick cache did during one render.
struct BrickCacheStats {
    uint64_t bricks_written = 0;
    uint64_t reads = 0;       ///< loads served from the cache
    uint64_t disk_bytes = 0;  ///< bytes the cached meshes take on disk
    uint64_t mesh_bytes = 0;  ///< bytes they take decoded
    uint64_t skipped = 0;     ///< meshes not cached: over the limit, or after a write error
};

/// Thread-safe: any loader may Put and Get at once (one brick is loaded by one thread at a time).
class BrickCache {
  public:
    /// Caches up to `limit_bytes` on disk in `file`, for bricks 0 .. brick_count-1.
    BrickCache(std::unique_ptr<store::SpillFile> file, uint32_t brick_count, uint64_t limit_bytes);
    ~BrickCache();

    /// Whether brick `id`'s mesh is cached.
    bool Has(uint32_t id) const;
    /// Caches `mesh` for brick `id` unless it is cached already or the cache is full. A write
    /// error stops the caching (one warning, naming the directory): the render goes on without.
    void Put(uint32_t id, const store::BrickMesh& mesh);
    /// Reads brick `id`'s mesh back into pages of its own (Has(id) must be true). Errors name the
    /// brick.
    StatusOr<ResidentMesh> Get(uint32_t id) const;

    BrickCacheStats stats() const;
    const store::SpillFile& file() const { return *file_; }

  private:
    struct Entry {
        std::atomic<bool> ready{false};
        MeshCounts counts;
        store::SpillExtent positions, normal_data, uv_data, indices, materials;
    };
    std::unique_ptr<store::SpillFile> file_;
    const uint64_t limit_bytes_;
    std::vector<std::unique_ptr<Entry>> entries_;
    mutable std::mutex mutex_;  // guards stats_ and failed_
    mutable BrickCacheStats stats_;
    bool failed_ = false;
};

}  // namespace nave::render
