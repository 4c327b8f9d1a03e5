#include "src/render/bricks/memory_brick_source.h"

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
      meshes_(std::move(meshes)) {}

uint64_t MemoryBrickSource::EstimatedResidentBytes(uint32_t id) const {
    const store::BrickMesh& m = meshes_[id];
    return ResidentBrick::EstimateMemoryBytes(m.VertexCount(), m.TriangleCount(), m.HasNormals(),
                                              m.HasUvs(), bvh_settings());
}

StatusOr<store::BrickMesh> MemoryBrickSource::LoadMesh(uint32_t id, uint64_t* bytes_read) {
    *bytes_read += meshes_[id].MemoryBytes();
    return meshes_[id];
}

}  // namespace nave::render
