#pragma once
// Access to the bricks of a model through pinned handles. The renderer never holds a brick except
// through a BrickHandle, and never assumes that a brick it does not hold is resident: which bricks
// stay in memory is the source's policy (StoreBrickSource keeps every brick it has loaded; the
// out-of-core pager replaces that policy under a memory budget). A resident brick carries its
// decoded mesh and its Embree scene, built when the brick is loaded. Embree types stay in
// brick_source.cpp.

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/resident_mesh.h"
#include "store/brick_mesh.h"
#include "store/brick_tree.h"
#include "store/material_record.h"

namespace nave {
class TraceRecorder;
}
namespace nave::store {
class Store;
}

namespace nave::render {

class EmbreeDevice;

/// A cut-out (alpha-masked leaves, chains, lead cames): whether the surface of one material is
/// there at mesh texture coordinates `uv`. Called by Embree's intersection filters from any thread,
/// so thread-safe.
class AlphaMask {
  public:
    virtual ~AlphaMask() = default;
    virtual bool Present(const std::array<float, 2>& uv) const = 0;
};
/// Alpha masks by material id; a null entry (or an id past the end) is an opaque material.
using AlphaMasks = std::vector<std::shared_ptr<const AlphaMask>>;

/// How Embree builds a brick's BVH. Quality trades build time for trace speed; compact nodes trade
/// trace speed for memory. Measured on abbey bricks by bench_brick_load (docs/pager.md, "Brick
/// loads").
struct BvhSettings {
    enum class Quality : uint8_t { kLow, kMedium, kHigh };
    // Low quality, compact nodes: on the detail-110 abbey the whole in-core render took 42 s
    // instead of 56 s with medium (a load is 2-3x cheaper, tracing slightly slower) and 7.6 GiB
    // instead of 9.1 GiB (docs/pager.md, "Brick loads").
    Quality quality = Quality::kLow;
    bool compact = true;
    /// Bytes Embree's BVH takes per triangle with these settings (measured upper bound, for
    /// budgets).
    uint64_t BytesPerTriangle() const;
    bool operator==(const BvhSettings&) const = default;
};

/// The nearest hit of a ray inside one brick.
struct BrickHit {
    float t = 0;         ///< ray parameter of the hit
    float u = 0, v = 0;  ///< barycentrics of vertices 1 and 2 (Embree's convention)
    uint32_t triangle = 0;
    Vec3f ng;  ///< geometric normal, unnormalised, (v1 - v0) x (v2 - v0): front side is CCW
};

/// A brick in memory: its cell, its mesh (shading data) and its Embree scene. Immutable once built,
/// so any number of threads may trace it at once. Built and destroyed only by a BrickSource.
class ResidentBrick {
  public:
    ~ResidentBrick();
    ResidentBrick(const ResidentBrick&) = delete;
    ResidentBrick& operator=(const ResidentBrick&) = delete;

    /// Builds the Embree scene over `mesh` (shared buffers: the mesh is not copied). Embree errors
    /// (out of memory, invalid geometry) come back as a Status naming the brick. With `masks`, hits
    /// on masked materials where the mask says the surface is absent are skipped by every query
    /// (the masks must outlive the brick).
    static StatusOr<std::unique_ptr<ResidentBrick>> Build(EmbreeDevice& device, uint32_t id,
                                                          Bounds3f cell, ResidentMesh mesh,
                                                          const AlphaMasks* masks = nullptr,
                                                          const BvhSettings& bvh = {});
    /// The same over a copy of `mesh`.
    static StatusOr<std::unique_ptr<ResidentBrick>> Build(EmbreeDevice& device, uint32_t id,
                                                          Bounds3f cell,
                                                          const store::BrickMesh& mesh,
                                                          const AlphaMasks* masks = nullptr,
                                                          const BvhSettings& bvh = {});

    uint32_t id() const { return id_; }
    const Bounds3f& cell() const { return cell_; }
    const ResidentMesh& mesh() const { return mesh_; }
    /// Bytes of the mesh plus an estimate of Embree's BVH (for budgets and statistics).
    uint64_t memory_bytes() const { return memory_bytes_; }
    /// memory_bytes() of a brick before it is loaded, from its counts (what a store's directory
    /// says). Exact: the pager checks it.
    static uint64_t EstimateMemoryBytes(uint64_t vertex_count, uint64_t triangle_count,
                                        bool has_normals, bool has_uvs,
                                        const BvhSettings& bvh = {});

    /// The nearest hit with t in [t0, t1], or false. Thread-safe.
    bool Intersect(const Vec3f& origin, const Vec3f& dir, float t0, float t1, BrickHit* hit) const;
    /// Whether any triangle is hit with t in [t0, t1]. Thread-safe.
    bool Occluded(const Vec3f& origin, const Vec3f& dir, float t0, float t1) const;

    /// Whether the surface of `triangle` is there at barycentrics (u, v) (its material's alpha
    /// mask).
    bool SurfacePresent(uint32_t triangle, float u, float v) const;

  private:
    ResidentBrick(uint32_t id, Bounds3f cell, ResidentMesh mesh);
    uint32_t id_;
    const AlphaMasks* masks_ = nullptr;
    Bounds3f cell_;
    ResidentMesh mesh_;
    void* scene_ = nullptr;  // RTCScene
    uint64_t memory_bytes_ = 0;
};

class BrickSource;
class BrickMeshCache;

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

    uint32_t brick_count() const { return uint32_t(slots_.size()); }
    const store::BrickTree& tree() const { return tree_; }
    /// The cell of every brick, by id.
    const std::vector<Bounds3f>& cells() const { return cells_; }
    const std::vector<store::MaterialRecord>& materials() const { return materials_; }
    /// Box of all geometry.
    const Bounds3f& bounds() const { return bounds_; }

    /// Pins brick `id`, loading it first if it is not resident. Errors (corrupt brick, Embree
    /// failure) name the brick and are returned to every caller that asks for it.
    StatusOr<BrickHandle> Acquire(uint32_t id);
    /// Whether brick `id` is in memory now (a hint: it may be evicted right after unless pinned).
    bool IsResident(uint32_t id) const;
    /// Drops brick `id` from memory if nobody pins it; returns whether it was dropped. The pager's
    /// tool; the default policy never calls it.
    bool Evict(uint32_t id);
    /// What brick `id` will take in memory once loaded (ResidentBrick::memory_bytes), known without
    /// loading it.
    virtual uint64_t EstimatedResidentBytes(uint32_t id) const = 0;
    BrickSourceStats stats() const;
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
    void SetMeshCache(BrickMeshCache* cache) { mesh_cache_ = cache; }
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
    /// Reads and decodes brick `id` (no caching: the base class caches). Adds to `bytes_read`.
    virtual StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) = 0;

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
    std::shared_ptr<EmbreeDevice> device_;
    store::BrickTree tree_;
    std::vector<Bounds3f> cells_;
    std::vector<store::MaterialRecord> materials_;
    Bounds3f bounds_;
    AlphaMasks alpha_masks_;
    BvhSettings bvh_;
    TraceRecorder* trace_ = nullptr;
    BrickMeshCache* mesh_cache_ = nullptr;
    int decode_limit_ = 0;
    std::mutex decode_mutex_;  // with decode_cv_: counts decodes_ under decode_limit_
    std::condition_variable decode_cv_;
    int decodes_ = 0;
    std::vector<std::unique_ptr<Slot>> slots_;
    mutable std::mutex stats_mutex_;
    BrickSourceStats stats_;
    std::atomic<uint64_t> acquires_{0};
};

/// Bricks read from a store file on first touch and kept resident.
class StoreBrickSource final : public BrickSource {
  public:
    static StatusOr<std::unique_ptr<StoreBrickSource>> Open(const std::filesystem::path& path,
                                                            std::shared_ptr<EmbreeDevice> device);
    ~StoreBrickSource() override;
    const store::Store& store() const { return *store_; }
    uint64_t EstimatedResidentBytes(uint32_t id) const override;
    uint64_t LoadScratchBytes(uint32_t id) const override;

  protected:
    StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) override;

  private:
    StoreBrickSource(std::unique_ptr<store::Store> store, std::shared_ptr<EmbreeDevice> device);
    std::unique_ptr<store::Store> store_;
};

/// Bricks held in memory from the start (tests, benchmarks). "Loading" copies the mesh.
class MemoryBrickSource final : public BrickSource {
  public:
    MemoryBrickSource(std::shared_ptr<EmbreeDevice> device, store::BrickTree tree,
                      std::vector<store::BrickMesh> meshes,
                      std::vector<store::MaterialRecord> materials);
    uint64_t EstimatedResidentBytes(uint32_t id) const override;

  protected:
    StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) override;

  private:
    std::vector<store::BrickMesh> meshes_;
};

/// The process's Embree device. Embree errors reported through its callback are kept and turned
/// into a Status by the call that caused them.
class EmbreeDevice {
  public:
    /// `config` is Embree's device configuration string ("threads=4"); empty for the defaults.
    static StatusOr<std::shared_ptr<EmbreeDevice>> Create(const std::string& config = "");
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    void* handle() const { return device_; }  // RTCDevice
    /// The last error reported by Embree's callback (and clears it), or Ok.
    Status TakeError(const std::string& context);

  private:
    EmbreeDevice() = default;
    static void ErrorCallback(void* user, int code, const char* message);
    void* device_ = nullptr;
    std::mutex mutex_;
    Status error_;
};

}  // namespace nave::render
