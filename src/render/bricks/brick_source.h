#pragma once
// Access to the bricks of a model through pinned handles. The renderer never holds a brick except
// through a BrickHandle, and never assumes that a brick it does not hold is resident: which bricks
// stay in memory is the source's policy (StoreBrickSource keeps every brick it has loaded; the
// out-of-core pager replaces that policy under a memory budget). A resident brick carries its
// decoded mesh and its Embree scene, built when the brick is loaded (resident_brick.h).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/bricks/embree_device.h"
#include "src/render/bricks/resident_brick.h"
#include "store/brick_mesh.h"
#include "store/brick_tree.h"
#include "store/material_record.h"
#include "store/occupancy_grid.h"

namespace nave {
class TraceRecorder;
}

namespace nave::render {

class BrickSource;
class BrickCache;

/// A pin on a resident brick: while a handle lives, its brick stays in memory. Move-only; releasing
/// (or destroying) the handle unpins it.
class BrickHandle {
  public:
    BrickHandle() = default;
    BrickHandle(BrickSource* source, const ResidentBrick* brick) : source_(source), brick_(brick) {}
    BrickHandle(BrickHandle&& o) noexcept : source_(o.source_), brick_(o.brick_) {
        o.source_ = nullptr;
        o.brick_ = nullptr;
    }
    BrickHandle& operator=(BrickHandle&& o) noexcept;
    BrickHandle(const BrickHandle&) = delete;
    BrickHandle& operator=(const BrickHandle&) = delete;
    ~BrickHandle() { Reset(); }

    void Reset();
    const ResidentBrick* get() const { return brick_; }
    const ResidentBrick* operator->() const { return brick_; }
    const ResidentBrick& operator*() const { return *brick_; }
    explicit operator bool() const { return brick_ != nullptr; }

  private:
    BrickSource* source_ = nullptr;
    const ResidentBrick* brick_ = nullptr;
};

/// Counters a source keeps for the final statistics (all since creation).
struct BrickSourceStats {
    uint64_t acquires = 0;        ///< Acquire calls (brick visits)
    uint64_t loads = 0;           ///< bricks read and built
    uint64_t evictions = 0;       ///< bricks dropped from memory
    uint64_t bytes_read = 0;      ///< payload bytes read from disk
    uint64_t resident_bytes = 0;  ///< bytes of the bricks in memory now
    uint64_t peak_resident_bytes = 0;
    double load_seconds = 0;  ///< time spent reading, decoding and building Embree scenes
};

/// Where bricks come from, and which stay resident. Thread-safe: many workers may acquire at once;
/// loading one brick never blocks acquiring another that is already resident (one lock per brick,
/// double-checked as in OpenVDB's LeafBuffer).
class BrickSource {
  public:
    virtual ~BrickSource();

    /// Bricks: the leaves of the brick tree, each a cell of space.
    uint32_t brick_count() const { return brick_count_; }
    const store::BrickTree& tree() const { return tree_; }

    /// Levels of detail (docs/render.md, "Levels of detail"). Level 0 of a brick is its full mesh;
    /// a store may hold coarser ones, each with its error (store::LevelInfo). The stream layer
    /// sees each level of each brick as a slot of its own, with its own queue and residency:
    /// slot = level * brick_count() + brick. Without levels (UseLevels(1), the default) slots are
    /// bricks. Everything that takes a brick id below (Acquire, Evict, IsResident, the estimates)
    /// takes a slot.
    uint32_t slot_count() const { return uint32_t(slots_.size()); }
    /// Levels per brick in use (1: full detail only).
    uint32_t level_count() const { return level_count_; }
    uint32_t BrickOfSlot(uint32_t slot) const { return slot % brick_count_; }
    uint32_t LevelOfSlot(uint32_t slot) const { return slot / brick_count_; }
    uint32_t SlotOf(uint32_t brick, uint32_t level) const { return level * brick_count_ + brick; }
    /// The errors of brick `brick`'s levels in use, finest first: level_count() values, 0 for level
    /// 0 and +infinity for a level the brick lacks (so that no footprint chooses it).
    const float* LevelErrors(uint32_t brick) const { return &level_errors_[brick * level_count_]; }
    /// Levels brick `brick` has in use (1 to level_count()).
    uint32_t LevelsOf(uint32_t brick) const;
    /// Uses up to `max_levels` levels of each brick (1: full detail everywhere; more than the
    /// model has: all it has). InvalidArgument if any brick is resident.
    Status UseLevels(uint32_t max_levels);
    /// The cell of every brick, by id.
    const std::vector<Bounds3f>& cells() const { return cells_; }
    const std::vector<store::MaterialRecord>& materials() const { return materials_; }
    /// Box of all geometry.
    const Bounds3f& bounds() const { return bounds_; }

    /// Pins slot `id` (a brick at one of its levels), loading it first if it is not resident.
    /// Errors (corrupt brick, Embree failure) name the brick and are returned to every caller that
    /// asks for it.
    StatusOr<BrickHandle> Acquire(uint32_t id);
    /// Whether brick `id` is in memory now (a hint: it may be evicted right after unless pinned).
    bool IsResident(uint32_t id) const;
    /// Drops brick `id` from memory if nobody pins it; returns whether it was dropped. The pager's
    /// tool; the default policy never calls it.
    bool Evict(uint32_t id);
    /// What brick `id` will take in memory once loaded (ResidentBrick::memory_bytes, with its
    /// piece of a stored medium once UseStoredMedium), known without loading it.
    uint64_t EstimatedResidentBytes(uint32_t id) const {
        return EstimatedMeshBytes(id) + (medium_scale_ ? MediumPieceBytes(BrickOfSlot(id)) : 0);
    }
    /// Every brick loaded from now on comes with its piece of the medium grid the source holds
    /// (ResidentBrick::medium), its values times `scale`; every level of a brick carries the same
    /// piece. NotFound if the source holds no medium grid; InvalidArgument if bricks are resident.
    Status UseStoredMedium(float scale);
    BrickSourceStats stats() const;
    /// Whether each brick's first full-detail load from now on makes its occupancy grid (off by
    /// default: only renders that pass over bricks crossed in air read them). Thread-safe.
    void MakeOccupancyGrids(bool on) { make_occupancy_.store(on, std::memory_order_relaxed); }
    /// Whether every brick's occupancy grid is known from the start (SetOccupancy: a store's, or
    /// one made from meshes held in memory), so that passing over bricks crossed in air routes
    /// rays the same way in every run.
    bool occupancy_known() const { return occupancy_known_; }
    /// Where brick `brick`'s full mesh has triangles (store::OccupancyGrid): known from the start
    /// (occupancy_known), or once it has been loaded at full detail with MakeOccupancyGrids on;
    /// null before. Kept when the brick is evicted: store::OccupancyGrid::kMemoryBytes per brick,
    /// counted by the memory plan. Thread-safe.
    const store::OccupancyGrid* Occupancy(uint32_t brick) const {
        return occupancy_[brick].grid.load(std::memory_order_acquire);
    }
    /// The Embree device the bricks are built on (for small auxiliary scenes, like the photon
    /// portals).
    EmbreeDevice& device() const { return *device_; }
    /// Cut-outs by material id, applied to every brick built from now on. Call before any brick is
    /// loaded (checked): a resident brick keeps the masks it was built with.
    void SetAlphaMasks(AlphaMasks masks);
    /// How bricks build their BVH (and what EstimatedResidentBytes assumes). FailedPrecondition if
    /// bricks built otherwise are resident (they would not match the estimates).
    Status SetBvhSettings(const BvhSettings& bvh);
    const BvhSettings& bvh_settings() const { return bvh_; }
    /// Records every load (read and decode, BVH build) as spans on `trace` (null: no tracing). Set
    /// before loads start; `trace` must outlive them.
    void SetTrace(TraceRecorder* trace) { trace_ = trace; }
    /// Loads read decoded meshes back from `cache` when it has them, and put there those they
    /// decode (null: every load decodes from the store). Set before loads start; `cache` must
    /// outlive them.
    void SetBrickCache(BrickCache* cache) { brick_cache_ = cache; }
    /// At most `limit` loads decode at once (0: no limit); under a budget one decode's scratch
    /// memory is reserved, not one per loader. Set before loads start.
    void SetDecodeLimit(int limit) { decode_limit_ = limit; }
    /// Memory a load of brick `id` needs beside the brick itself while it decodes (0 for sources
    /// that do not decode).
    virtual uint64_t LoadScratchBytes(uint32_t id) const {
        (void)id;
        return 0;
    }

  protected:
    BrickSource(std::shared_ptr<EmbreeDevice> device, store::BrickTree tree,
                std::vector<Bounds3f> cells, std::vector<store::MaterialRecord> materials,
                Bounds3f bounds);
    /// Gives every brick its occupancy grid before anything loads: `grids[b]` brick b's (null for
    /// a brick of no triangles, which no ray can meet); occupancy_known from then on.
    void SetOccupancy(std::vector<std::unique_ptr<const store::OccupancyGrid>> grids);
    /// Reads and decodes slot `id` (no caching: the base class caches). Adds to `bytes_read`.
    virtual StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) = 0;
    /// What slot `id`'s mesh and BVH take once loaded (ResidentBrick::memory_bytes without a
    /// medium).
    virtual uint64_t EstimatedMeshBytes(uint32_t id) const = 0;
    /// Whether the source holds a medium grid cut into its bricks; a message saying why not.
    virtual Status HasStoredMedium() const {
        return NotFoundError(
            "the model holds no medium grid: `nave preprocess` stores one given "
            "a .vdb file beside the model");
    }
    /// Brick `brick`'s piece of it times `scale`, counted inside its cell (null: no voxels there),
    /// read and decoded; adds to `bytes_read`.
    virtual StatusOr<std::shared_ptr<const DensityField>> LoadMediumPiece(uint32_t brick,
                                                                          float scale,
                                                                          uint64_t* bytes_read) {
        (void)brick;
        (void)scale;
        (void)bytes_read;
        return std::shared_ptr<const DensityField>();
    }
    /// What that piece takes in memory.
    virtual uint64_t MediumPieceBytes(uint32_t brick) const {
        (void)brick;
        return 0;
    }
    /// Levels brick `brick` has, level 0 included (1: no coarser level).
    virtual uint32_t StoredLevels(uint32_t brick) const {
        (void)brick;
        return 1;
    }
    /// The error of brick `brick`'s level `level` (< StoredLevels), in model units.
    virtual float StoredLevelError(uint32_t brick, uint32_t level) const {
        (void)brick;
        (void)level;
        return 0;
    }

  private:
    friend class BrickHandle;
    void Release(uint32_t id);

    struct Slot {
        std::mutex mutex;  // held while loading this brick
        std::atomic<const ResidentBrick*> ready{nullptr};
        std::unique_ptr<ResidentBrick> brick;
        std::atomic<uint32_t> pins{0};
        Status error;  // sticky load error
    };
    // A brick's occupancy grid (Occupancy): set before rendering (SetOccupancy) or made at its
    // first full-detail load (MakeOccupancyGrids), and kept through evictions.
    struct BrickOccupancy {
        std::unique_ptr<const store::OccupancyGrid> owned;
        std::atomic<const store::OccupancyGrid*> grid{nullptr};
    };
    std::shared_ptr<EmbreeDevice> device_;
    store::BrickTree tree_;
    std::vector<Bounds3f> cells_;
    std::vector<store::MaterialRecord> materials_;
    Bounds3f bounds_;
    AlphaMasks alpha_masks_;
    BvhSettings bvh_;
    TraceRecorder* trace_ = nullptr;
    BrickCache* brick_cache_ = nullptr;
    int decode_limit_ = 0;
    std::atomic<bool> make_occupancy_{false};  // MakeOccupancyGrids
    bool occupancy_known_ = false;             // every brick's grid set before rendering
    // By brick, apart from the slots (which UseLevels makes again).
    std::unique_ptr<BrickOccupancy[]> occupancy_;
    std::optional<float> medium_scale_;  // UseStoredMedium's
    std::mutex decode_mutex_;            // with decode_cv_: counts decodes_ under decode_limit_
    std::condition_variable decode_cv_;
    int decodes_ = 0;
    uint32_t brick_count_ = 0;
    uint32_t level_count_ = 1;
    std::vector<float> level_errors_;  // level_count_ per brick
    float coarsest_error_ = 0;         // the largest of level_errors_
    std::vector<std::unique_ptr<Slot>> slots_;
    mutable std::mutex stats_mutex_;
    BrickSourceStats stats_;
    std::atomic<uint64_t> acquires_{0};
};

}  // namespace nave::render
