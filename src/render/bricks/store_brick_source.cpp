#include "src/render/bricks/store_brick_source.h"

#include "src/render/bricks/vdb_density.h"
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
    std::unique_ptr<StoreBrickSource> source(
        new StoreBrickSource(std::move(st), std::move(device)));
    NAVE_RETURN_IF_ERROR(source->ReadOccupancy());
    return source;
}

Status StoreBrickSource::ReadOccupancy() {
    const std::vector<store::BrickInfo>& bricks = store_->bricks();
    // Known only if every brick a ray can meet has its grid (a store of format 3.4).
    for (const store::BrickInfo& b : bricks)
        if (b.triangle_count > 0 && b.occupancy.length == 0) return Status::Ok();
    std::vector<std::unique_ptr<const store::OccupancyGrid>> grids(bricks.size());
    for (uint32_t b = 0; b < bricks.size(); ++b) {
        if (bricks[b].occupancy.length == 0) continue;
        NAVE_ASSIGN_OR_RETURN(store::OccupancyGrid grid, store_->ReadBrickOccupancy(b));
        grids[b] = std::make_unique<const store::OccupancyGrid>(std::move(grid));
    }
    SetOccupancy(std::move(grids));
    return Status::Ok();
}

namespace {
/// The counts of brick `info` at `level` (0: the brick itself).
struct LevelCounts {
    uint64_t vertices, triangles;
    bool normals, uvs;
    uint64_t disk_bytes;
};
LevelCounts CountsOf(const store::BrickInfo& info, uint32_t level) {
    if (level == 0) {
        return {info.vertex_count, info.triangle_count, info.has_normals, info.has_uvs,
                info.BytesOnDisk()};
    }
    const store::LevelInfo& l = info.levels[level - 1];
    return {l.vertex_count, l.triangle_count, l.has_normals, l.has_uvs, l.mesh.length};
}
}  // namespace

uint32_t StoreBrickSource::StoredLevels(uint32_t brick) const {
    return 1 + uint32_t(store_->bricks()[brick].levels.size());
}

float StoreBrickSource::StoredLevelError(uint32_t brick, uint32_t level) const {
    return level == 0 ? 0.f : store_->bricks()[brick].levels[level - 1].error;
}

uint64_t StoreBrickSource::EstimatedMeshBytes(uint32_t id) const {
    const uint32_t brick = BrickOfSlot(id), level = LevelOfSlot(id);
    if (level >= LevelsOf(brick)) return 0;  // a level this brick lacks: never loaded
    const LevelCounts c = CountsOf(store_->bricks()[brick], level);
    return ResidentBrick::EstimateMemoryBytes(c.vertices, c.triangles, c.normals, c.uvs,
                                              bvh_settings());
}

uint64_t StoreBrickSource::LoadScratchBytes(uint32_t id) const {
    // Draco's decoder holds its own mesh, corner table and attribute buffers beside ours: `nave
    // verify --threads 1` of the detail-110 abbey (bricks of up to 780 k triangles) peaks 114 MiB
    // above the process's size, 28 MiB of it the decoded brick: about 110 bytes per triangle.
    constexpr uint64_t kDecodeScratchBytesPerTriangle = 112;
    const uint32_t brick = BrickOfSlot(id), level = LevelOfSlot(id);
    if (level >= LevelsOf(brick)) return 0;
    return kDecodeScratchBytesPerTriangle * CountsOf(store_->bricks()[brick], level).triangles;
}

StatusOr<store::BrickMesh> StoreBrickSource::LoadMesh(uint32_t id, uint64_t* bytes_read) {
    const uint32_t brick = BrickOfSlot(id), level = LevelOfSlot(id);
    NAVE_ASSIGN_OR_RETURN(store::BrickMesh mesh, store_->ReadBrick(brick, level));
    *bytes_read += CountsOf(store_->bricks()[brick], level).disk_bytes;
    return mesh;
}

Status StoreBrickSource::HasStoredMedium() const {
    if (store_->header().medium_grid.empty())
        return NotFoundError(
            "{} holds no medium grid: `nave preprocess` stores one given a .vdb file beside the "
            "model",
            store_->path().string());
    return Status::Ok();
}

StatusOr<std::shared_ptr<const DensityField>> StoreBrickSource::LoadMediumPiece(
    uint32_t brick, float scale, uint64_t* bytes_read) {
    const store::BrickInfo& info = store_->bricks()[brick];
    if (info.medium.grid.length == 0) return std::shared_ptr<const DensityField>();
    NAVE_ASSIGN_OR_RETURN(const std::vector<std::byte> bytes, store_->ReadBrickMedium(brick));
    *bytes_read += info.medium.grid.length;
    NAVE_ASSIGN_OR_RETURN(
        std::shared_ptr<const VdbDensity> piece,
        VdbDensity::FromPiece(bytes,
                              fmt::format("{} brick {} medium", store_->path().string(), brick),
                              scale, cells()[brick]));
    return std::shared_ptr<const DensityField>(std::move(piece));
}

uint64_t StoreBrickSource::MediumPieceBytes(uint32_t brick) const {
    return store_->bricks()[brick].medium.decoded_bytes;
}

}  // namespace nave::render
