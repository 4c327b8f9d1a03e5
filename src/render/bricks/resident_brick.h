#pragma once
// A brick in memory: its decoded mesh and its Embree scene, built when the brick is loaded, with
// the cut-outs its intersection filters consult. Embree types stay in resident_brick.cpp.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/bricks/density_field.h"
#include "src/render/bricks/embree_device.h"
#include "src/render/bricks/resident_mesh.h"
#include "store/brick_mesh.h"

namespace nave {
class TraceRecorder;
}

namespace nave::render {

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

/// Which level of detail of its brick a resident brick holds (BrickSource, "Levels of detail").
struct LevelOfDetail {
    uint32_t level = 0;  ///< 0: the full mesh
    float error = 0;     ///< the level's largest distance from the full surface, model units
    /// The largest error of any level of the model in use (0 without levels): how far off a
    /// surface a ray may meet another level's copy of it (LevelReach).
    float coarsest_error = 0;
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
                                                          const BvhSettings& bvh = {},
                                                          LevelOfDetail lod = {});
    /// The same over a copy of `mesh`.
    static StatusOr<std::unique_ptr<ResidentBrick>> Build(EmbreeDevice& device, uint32_t id,
                                                          Bounds3f cell,
                                                          const store::BrickMesh& mesh,
                                                          const AlphaMasks* masks = nullptr,
                                                          const BvhSettings& bvh = {});

    /// The brick's slot in its source (BrickSource::SlotOf: the brick id at level 0).
    uint32_t id() const { return id_; }
    const LevelOfDetail& lod() const { return lod_; }
    const Bounds3f& cell() const { return cell_; }
    const ResidentMesh& mesh() const { return mesh_; }
    /// Bytes of the mesh plus an estimate of Embree's BVH, plus the medium's piece (for budgets
    /// and statistics).
    uint64_t memory_bytes() const { return memory_bytes_; }
    /// The brick's piece of a medium stored in the bricks (Medium::DensityIn), counted inside the
    /// cell only; null when it has none or no such medium is rendered.
    const DensityField* medium() const { return medium_.get(); }
    /// Gives the brick its piece of the stored medium, which takes `bytes`. Only its BrickSource
    /// calls it, before any other thread sees the brick.
    void AttachMedium(std::shared_ptr<const DensityField> medium, uint64_t bytes) {
        medium_ = std::move(medium);
        memory_bytes_ += bytes;
    }
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
    LevelOfDetail lod_;
    const AlphaMasks* masks_ = nullptr;
    Bounds3f cell_;
    ResidentMesh mesh_;
    void* scene_ = nullptr;  // RTCScene
    std::shared_ptr<const DensityField> medium_;
    uint64_t memory_bytes_ = 0;
};

}  // namespace nave::render
