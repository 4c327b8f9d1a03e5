#include "src/render/bricks/memory_brick_source.h"

#include "src/core/check.h"

namespace nave::render {

namespace {
Bounds3f MeshesBounds(const std::vector<store::BrickMesh>& meshes) {
    Bounds3f b;
    for (const auto& m : meshes) {
        for (const Vec3f& p : m.positions) b.Extend(p);
    }
    return b;
}
}  // namespace

MemoryBrickSource::MemoryBrickSource(std::shared_ptr<EmbreeDevice> device,
                                     const store::BrickTree& tree,
                                     std::vector<store::BrickMesh> meshes,
                                     std::vector<store::MaterialRecord> materials)
    : BrickSource(std::move(device), tree, tree.BrickCells(uint32_t(meshes.size())),
                  std::move(materials), MeshesBounds(meshes)),
      meshes_(std::move(meshes)),
      levels_(meshes_.size()) {}

MemoryBrickSource::MemoryBrickSource(std::shared_ptr<EmbreeDevice> device,
                                     const store::BrickTree& tree,
                                     std::vector<store::BrickMesh> meshes,
                                     std::vector<store::MaterialRecord> materials,
                                     std::vector<std::vector<store::BrickLevel>> levels)
    : MemoryBrickSource(std::move(device), tree, std::move(meshes), std::move(materials)) {
    NAVE_CHECK_EQ(levels.size(), meshes_.size());
    levels_ = std::move(levels);
}

void MemoryBrickSource::KnowOccupancy() {
    std::vector<std::unique_ptr<const store::OccupancyGrid>> grids(meshes_.size());
    for (size_t b = 0; b < meshes_.size(); ++b) {
        if (meshes_[b].TriangleCount() == 0) continue;
        grids[b] = std::make_unique<const store::OccupancyGrid>(
            store::OccupancyGrid::Of(meshes_[b].positions, meshes_[b].indices));
    }
    SetOccupancy(std::move(grids));
}

const store::BrickMesh* MemoryBrickSource::MeshOf(uint32_t id) const {
    const uint32_t brick = BrickOfSlot(id), level = LevelOfSlot(id);
    if (level == 0) return &meshes_[brick];
    return level <= levels_[brick].size() ? &levels_[brick][level - 1].mesh : nullptr;
}

uint32_t MemoryBrickSource::StoredLevels(uint32_t brick) const {
    return 1 + uint32_t(levels_[brick].size());
}

float MemoryBrickSource::StoredLevelError(uint32_t brick, uint32_t level) const {
    return level == 0 ? 0.f : levels_[brick][level - 1].error;
}

uint64_t MemoryBrickSource::EstimatedMeshBytes(uint32_t id) const {
    const store::BrickMesh* m = MeshOf(id);
    if (m == nullptr) return 0;
    return ResidentBrick::EstimateMemoryBytes(m->VertexCount(), m->TriangleCount(), m->HasNormals(),
                                              m->HasUvs(), bvh_settings());
}

StatusOr<store::BrickMesh> MemoryBrickSource::LoadMesh(uint32_t id, uint64_t* bytes_read) {
    const store::BrickMesh* m = MeshOf(id);
    if (m == nullptr)
        return NotFoundError("brick {} has no level {}", BrickOfSlot(id), LevelOfSlot(id));
    *bytes_read += m->MemoryBytes();
    return *m;
}

Status MemoryBrickSource::HasStoredMedium() const {
    return medium_ ? Status::Ok() : BrickSource::HasStoredMedium();
}

StatusOr<std::shared_ptr<const DensityField>> MemoryBrickSource::LoadMediumPiece(
    uint32_t brick, float scale, uint64_t* bytes_read) {
    (void)bytes_read;
    return std::shared_ptr<const DensityField>(
        std::make_shared<CellShare>(medium_, cells()[brick], scale));
}

}  // namespace nave::render
