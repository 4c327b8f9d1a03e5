#pragma once
// Bricks held in memory from the start, for tests and benchmarks.

#include <cstdint>
#include <memory>
#include <vector>

#include "src/render/bricks/brick_source.h"
#include "store/brick_levels.h"
#include "store/brick_mesh.h"
#include "store/brick_tree.h"
#include "store/material_record.h"

namespace nave::render {

/// Bricks held in memory from the start (tests, benchmarks). "Loading" copies the mesh.
class MemoryBrickSource final : public BrickSource {
  public:
    MemoryBrickSource(std::shared_ptr<EmbreeDevice> device, const store::BrickTree& tree,
                      std::vector<store::BrickMesh> meshes,
                      std::vector<store::MaterialRecord> materials);
    /// With coarser levels of each brick (store::MakeBrickLevels), used once UseLevels asks.
    MemoryBrickSource(std::shared_ptr<EmbreeDevice> device, const store::BrickTree& tree,
                      std::vector<store::BrickMesh> meshes,
                      std::vector<store::MaterialRecord> materials,
                      std::vector<std::vector<store::BrickLevel>> levels);
    /// Holds `whole` as the medium cut into the bricks (UseStoredMedium): each brick's piece is its
    /// CellShare. Call before UseStoredMedium.
    void HoldMedium(std::shared_ptr<const DensityField> whole) { medium_ = std::move(whole); }
    /// Makes every brick's occupancy grid now, as a store of format 3.4 holds them
    /// (occupancy_known): rays then pass over bricks crossed in air from the start, as they do
    /// over a store's. Call before rendering.
    void KnowOccupancy();

  protected:
    StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) override;
    uint64_t EstimatedMeshBytes(uint32_t id) const override;
    uint32_t StoredLevels(uint32_t brick) const override;
    float StoredLevelError(uint32_t brick, uint32_t level) const override;
    Status HasStoredMedium() const override;
    StatusOr<std::shared_ptr<const DensityField>> LoadMediumPiece(uint32_t brick, float scale,
                                                                  uint64_t* bytes_read) override;

  private:
    /// Slot `id`'s mesh, or null for a level its brick lacks.
    const store::BrickMesh* MeshOf(uint32_t id) const;
    std::vector<store::BrickMesh> meshes_;
    std::vector<std::vector<store::BrickLevel>> levels_;  // per brick, coarser levels
    std::shared_ptr<const DensityField> medium_;          // HoldMedium's
};

}  // namespace nave::render
