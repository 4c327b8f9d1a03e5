#pragma once
// Bricks held in memory from the start, for tests and benchmarks.

#include <cstdint>
#include <memory>
#include <vector>

#include "src/render/bricks/brick_source.h"
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
    uint64_t EstimatedResidentBytes(uint32_t id) const override;

  protected:
    StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) override;

  private:
    std::vector<store::BrickMesh> meshes_;
};

}  // namespace nave::render
