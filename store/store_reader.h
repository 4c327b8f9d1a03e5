#pragma once
// Reading a store. Open() reads the header, the directory, the brick tree and the material table
// only; bricks are read on demand, their checksums verified, then decoded. Every error names the
// file, the brick and the byte offset, with the expected and found values. Store is immutable after
// Open and thread-safe: many threads may read bricks at once (positional reads, no shared file
// offset).

#include <cstddef>
#include <filesystem>
#include <memory>
#include <vector>

#include "src/core/status.h"
#include "store/brick_mesh.h"
#include "store/brick_tree.h"
#include "store/material_record.h"
#include "store/occupancy_grid.h"
#include "store/store_info.h"

namespace nave::store {

class Store {
  public:
    /// Opens and checks header, tables and their checksums. Refuses another major version (naming
    /// both).
    static StatusOr<std::unique_ptr<Store>> Open(const std::filesystem::path& path);
    ~Store();

    const std::filesystem::path& path() const;
    const StoreHeader& header() const;
    const std::vector<BrickInfo>& bricks() const;
    const BrickTree& tree() const;
    const std::vector<MaterialRecord>& materials() const;
    uint64_t file_size() const;

    /// Reads, verifies and decodes brick `id` at `level` (0: the brick itself; k: its level k,
    /// BrickInfo::levels[k - 1]). Thread-safe. Adds the bytes read to bytes_read(). NotFound for a
    /// brick or level that does not exist; DataLoss for a checksum or a decoded count that
    /// disagrees with the tables.
    StatusOr<BrickMesh> ReadBrick(uint32_t id, uint32_t level = 0) const;
    /// The bytes of brick `id`'s piece of the medium (BrickInfo::medium: OpenVDB's serialization of
    /// a float grid, which volumes::VdbPlugin::ReadScalarGridBytes reads), its checksum verified.
    /// Thread-safe. Adds the bytes read to bytes_read(). NotFound for a brick that does not exist
    /// or holds no piece; DataLoss for a checksum that disagrees (naming the brick, the offset and
    /// both checksums).
    StatusOr<std::vector<std::byte>> ReadBrickMedium(uint32_t id) const;
    /// Brick `id`'s occupancy grid (BrickInfo::occupancy, format 3.4: where its full mesh has
    /// triangles), its checksum verified. Thread-safe. Adds the bytes read to bytes_read().
    /// NotFound for a brick that does not exist or has none; DataLoss for a checksum that
    /// disagrees or bytes that are not a grid (naming the brick and the offset).
    StatusOr<OccupancyGrid> ReadBrickOccupancy(uint32_t id) const;
    /// Reads brick `id`, each of its levels, its piece of the medium and its occupancy grid, and
    /// checks their
    /// checksums and that the meshes decode to the tables' counts (the medium's decoding is the
    /// OpenVDB plugin's: `nave verify` does it).
    Status VerifyBrick(uint32_t id) const;
    /// Total payload bytes read from disk since Open (for statistics).
    uint64_t bytes_read() const;

  private:
    struct Impl;
    explicit Store(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace nave::store
