#include "src/render/bricks/store_brick_source.h"

#include "store/store_reader.h"

namespace nave::render {

StoreBrickSource::StoreBrickSource(std::unique_ptr<store::Store> st,
                                   std::shared_ptr<EmbreeDevice> device)
    : BrickSource(std::move(device), st->tree(),
                  st->tree().BrickCells(uint32_t(st->bricks().size())), st->materials(),
                  st->header().bounds),
      store_(std::move(st)) {}

StoreBrickSource::~StoreBrickSource() = default;

StatusOr<std::unique_ptr<StoreBrickSource>> StoreBrickSource::Open(
    const std::filesystem::path& path, std::shared_ptr<EmbreeDevice> device) {
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<store::Store> st, store::Store::Open(path));
    return std::unique_ptr<StoreBrickSource>(
        new StoreBrickSource(std::move(st), std::move(device)));
}

uint64_t StoreBrickSource::EstimatedResidentBytes(uint32_t id) const {
    const store::BrickInfo& b = store_->bricks()[id];
    return ResidentBrick::EstimateMemoryBytes(b.vertex_count, b.triangle_count, b.has_normals,
                                              b.has_uvs, bvh_settings());
}

uint64_t StoreBrickSource::LoadScratchBytes(uint32_t id) const {
    // Draco's decoder holds its own mesh, corner table and attribute buffers beside ours: `nave
    // verify --threads 1` of the detail-110 abbey (bricks of up to 780 k triangles) peaks 114 MiB
    // above the process's size, 28 MiB of it the decoded brick: about 110 bytes per triangle.
    constexpr uint64_t kDecodeScratchBytesPerTriangle = 112;
    return kDecodeScratchBytesPerTriangle * store_->bricks()[id].triangle_count;
}

StatusOr<store::BrickMesh> StoreBrickSource::LoadMesh(uint32_t id, uint64_t* bytes_read) {
    NAVE_ASSIGN_OR_RETURN(store::BrickMesh mesh, store_->ReadBrick(id));
    *bytes_read += store_->bricks()[id].BytesOnDisk();
    return mesh;
}

}  // namespace nave::render
