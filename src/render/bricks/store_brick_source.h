#pragma once
// Bricks read from a store file (store/store_reader.h) on first touch.

#include <cstdint>
#include <filesystem>
#include <memory>

#include "src/core/status.h"
#include "src/render/bricks/brick_source.h"

namespace nave::store {
class Store;
}

namespace nave::render {

/// Bricks read from a store file on first touch and kept resident; their levels of detail are the
/// store's (store::LevelInfo).
class StoreBrickSource final : public BrickSource {
  public:
    static StatusOr<std::unique_ptr<StoreBrickSource>> Open(const std::filesystem::path& path,
                                                            std::shared_ptr<EmbreeDevice> device);
    ~StoreBrickSource() override;
    const store::Store& store() const { return *store_; }
    uint64_t LoadScratchBytes(uint32_t id) const override;

  protected:
    StatusOr<store::BrickMesh> LoadMesh(uint32_t id, uint64_t* bytes_read) override;
    uint64_t EstimatedMeshBytes(uint32_t id) const override;
    uint32_t StoredLevels(uint32_t brick) const override;
    float StoredLevelError(uint32_t brick, uint32_t level) const override;
    Status HasStoredMedium() const override;
    StatusOr<std::shared_ptr<const DensityField>> LoadMediumPiece(uint32_t brick, float scale,
                                                                  uint64_t* bytes_read) override;
    uint64_t MediumPieceBytes(uint32_t brick) const override;

  private:
    StoreBrickSource(std::unique_ptr<store::Store> store, std::shared_ptr<EmbreeDevice> device);
    /// Reads every brick's occupancy grid where the store holds them all (format 3.4), so that
    /// rays pass over bricks crossed in air from the start (BrickSource::occupancy_known). Errors:
    /// a grid whose checksum or bytes are wrong, naming the brick.
    Status ReadOccupancy();
    std::unique_ptr<store::Store> store_;
};

}  // namespace nave::render
