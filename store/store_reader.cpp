#include "store/store_reader.h"

#include <fmt/ostream.h>

#include <atomic>

#include "src/core/file.h"
#include "src/core/hash.h"
#include "store/brick_codec.h"
#include "store/store_format.h"

namespace nave::store {

struct Store::Impl {
    explicit Impl(ReadOnlyFile f) : file(std::move(f)) {}
    std::filesystem::path path;
    std::string name;  // the path as given, for messages
    ReadOnlyFile file;
    StoreHeader header;
    format::RawHeader raw;
    std::vector<BrickInfo> bricks;
    BrickTree tree;
    std::vector<MaterialRecord> materials;
    mutable std::atomic<uint64_t> bytes_read{0};

    // Reads a table and checks its checksum.
    StatusOr<std::string> ReadTable(const char* what, const SectionInfo& ref) const {
        std::string bytes(ref.length, '\0');
        NAVE_RETURN_IF_ERROR(file.ReadAt(ref.offset, bytes.data(), bytes.size()));
        const uint64_t checksum = Checksum64(bytes.data(), bytes.size());
        if (checksum != ref.checksum) {
            return DataLossError("{} {} table @0x{:x}: checksum {} != stored {}", name, what,
                                 ref.offset, ChecksumHex(checksum), ChecksumHex(ref.checksum));
        }
        return bytes;
    }

    // Reads one section of brick `id` into `bytes` (of its length) and checks its checksum.
    Status ReadSectionInto(uint32_t id, const std::string& what, const SectionInfo& s,
                           void* bytes) const {
        Status read = file.ReadAt(s.offset, bytes, s.length);
        if (!read.ok())
            return read.WithContext(
                fmt::format("{} brick {} @0x{:x} {} section", name, id, s.offset, what));
        bytes_read.fetch_add(s.length, std::memory_order_relaxed);
        const uint64_t checksum = Checksum64(bytes, s.length);
        if (checksum != s.checksum) {
            return DataLossError("{} brick {} @0x{:x}: {} checksum {} != stored {}", name, id,
                                 s.offset, what, ChecksumHex(checksum), ChecksumHex(s.checksum));
        }
        return Status::Ok();
    }

    StatusOr<std::string> ReadSection(uint32_t id, const std::string& what,
                                      const SectionInfo& s) const {
        std::string bytes(s.length, '\0');
        NAVE_RETURN_IF_ERROR(ReadSectionInto(id, what, s, bytes.data()));
        return bytes;
    }

    /// Brick `id`'s entry, or NotFound for a brick that does not exist.
    StatusOr<const BrickInfo*> Brick(uint32_t id) const {
        if (id >= bricks.size())
            return NotFoundError("{}: brick {} does not exist (the store has {} bricks)", name, id,
                                 bricks.size());
        return &bricks[id];
    }
};

namespace {

// A decoded mesh against the counts its table (`table`: "directory", "levels table") gave.
Status CheckCounts(const BrickMesh& mesh, const std::string& what, const char* table,
                   uint64_t triangles, uint64_t vertices, bool normals, bool uvs) {
    if (mesh.TriangleCount() != triangles || mesh.VertexCount() != vertices ||
        mesh.HasNormals() != normals || mesh.HasUvs() != uvs) {
        return DataLossError("{}: decoded {} triangles, {} vertices{}{} but the {} says {}, {}{}{}",
                             what, mesh.TriangleCount(), mesh.VertexCount(),
                             mesh.HasNormals() ? ", normals" : "", mesh.HasUvs() ? ", uvs" : "",
                             table, triangles, vertices, normals ? ", normals" : "",
                             uvs ? ", uvs" : "");
    }
    return Status::Ok();
}

}  // namespace

Store::Store(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Store::~Store() = default;

StatusOr<std::unique_ptr<Store>> Store::Open(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(ReadOnlyFile opened, ReadOnlyFile::Open(path));
    auto impl = std::make_unique<Impl>(std::move(opened));
    impl->path = path;
    impl->name = path.string();
    const std::string& name = impl->name;
    const ReadOnlyFile& file = impl->file;
    const uint64_t size = file.size();
    if (size == 0) {
        return DataLossError(
            "{}: empty file (0 bytes): not a nave store, or one whose writing never finished",
            name);
    }
    // The header records its own size; read enough for any header a 1.x writer may produce.
    std::string head(std::min<uint64_t>(size, 1u << 16), '\0');
    NAVE_RETURN_IF_ERROR(file.ReadAt(0, head.data(), head.size()));
    NAVE_ASSIGN_OR_RETURN(impl->raw, format::DecodeHeader(head, name, size));
    const format::RawHeader& h = impl->raw;

    NAVE_ASSIGN_OR_RETURN(std::string provenance_bytes,
                          impl->ReadTable("provenance", h.provenance));
    NAVE_ASSIGN_OR_RETURN(std::string directory_bytes, impl->ReadTable("directory", h.directory));
    NAVE_ASSIGN_OR_RETURN(std::string tree_bytes, impl->ReadTable("tree", h.tree));
    NAVE_ASSIGN_OR_RETURN(std::string material_bytes, impl->ReadTable("materials", h.materials));

    NAVE_ASSIGN_OR_RETURN(impl->header.provenance,
                          format::DecodeProvenance(provenance_bytes, name, h.provenance.offset));
    NAVE_ASSIGN_OR_RETURN(std::vector<format::RawBrickEntry> entries,
                          format::DecodeDirectory(directory_bytes, h, name));
    NAVE_ASSIGN_OR_RETURN(impl->tree, format::DecodeTree(tree_bytes, h, name));
    NAVE_ASSIGN_OR_RETURN(impl->materials, format::DecodeMaterials(material_bytes, h, name));
    if (h.levels.length > 0) {
        NAVE_ASSIGN_OR_RETURN(std::string level_bytes, impl->ReadTable("levels", h.levels));
        NAVE_RETURN_IF_ERROR(format::DecodeLevels(level_bytes, h, name, &entries));
    }
    if (h.occupancy.length > 0) {
        NAVE_ASSIGN_OR_RETURN(std::string occupancy_bytes,
                              impl->ReadTable("occupancy", h.occupancy));
        NAVE_RETURN_IF_ERROR(format::DecodeOccupancy(occupancy_bytes, h, name, &entries));
    }
    if (h.medium.length > 0) {
        NAVE_ASSIGN_OR_RETURN(std::string medium_bytes, impl->ReadTable("medium", h.medium));
        NAVE_RETURN_IF_ERROR(
            format::DecodeMedium(medium_bytes, h, name, &entries, &impl->header.medium_grid));
    }

    impl->header.major = h.major;
    impl->header.minor = h.minor;
    impl->header.grid = h.grid;
    impl->header.bounds = h.bounds;
    impl->header.triangle_count = h.triangle_count;
    impl->header.source_triangle_count = h.source_triangle_count;
    impl->header.header_checksum =
        Checksum64(head.data(), std::min<size_t>(head.size(), h.header_bytes));

    // Cross-checks between tables: each passed its checksum, so a failure here is a writer bug or a
    // deliberate edit, and still must not reach the renderer.
    uint64_t triangles = 0;
    impl->bricks.reserve(entries.size());
    for (const format::RawBrickEntry& e : entries) {
        const BrickInfo& b = e.info;
        const uint64_t entry_offset = h.directory.offset + uint64_t(b.id) * h.directory_entry_bytes;
        const uint64_t expected =
            BrickMesh::BytesFor(b.vertex_count, b.triangle_count, b.has_normals, b.has_uvs);
        if (b.decoded_bytes != expected) {
            return DataLossError(
                "{} brick {} @0x{:x}: decoded size {} != {} implied by its {} vertices and {} "
                "triangles",
                name, b.id, entry_offset, b.decoded_bytes, expected, b.vertex_count,
                b.triangle_count);
        }
        triangles += b.triangle_count;
        impl->bricks.push_back(b);
    }
    if (triangles != h.triangle_count) {
        return DataLossError("{}: the bricks hold {} triangles but the header says {}", name,
                             triangles, h.triangle_count);
    }
    std::vector<uint8_t> in_tree(h.brick_count, 0);
    for (const BrickTreeNode& n : impl->tree.nodes()) {
        if (n.IsLeaf() && n.brick != kNoBrick) in_tree[n.brick] = 1;
    }
    for (uint32_t b = 0; b < h.brick_count; ++b) {
        if (!in_tree[b])
            return DataLossError("{} tree @0x{:x}: brick {} is in no leaf", name, h.tree.offset, b);
    }
    return std::unique_ptr<Store>(new Store(std::move(impl)));
}

const std::filesystem::path& Store::path() const { return impl_->path; }
const StoreHeader& Store::header() const { return impl_->header; }
const std::vector<BrickInfo>& Store::bricks() const { return impl_->bricks; }
const BrickTree& Store::tree() const { return impl_->tree; }
const std::vector<MaterialRecord>& Store::materials() const { return impl_->materials; }
uint64_t Store::file_size() const { return impl_->file.size(); }
uint64_t Store::bytes_read() const { return impl_->bytes_read.load(std::memory_order_relaxed); }

StatusOr<BrickMesh> Store::ReadBrick(uint32_t id, uint32_t level) const {
    const Impl& s = *impl_;
    NAVE_ASSIGN_OR_RETURN(const BrickInfo* brick, s.Brick(id));
    const BrickInfo& info = *brick;
    if (level > info.levels.size()) {
        return NotFoundError("{}: brick {} has no level {} (its levels are 0 to {})", s.name, id,
                             level, info.levels.size());
    }
    if (level > 0) {
        const LevelInfo& l = info.levels[level - 1];
        const std::string what =
            fmt::format("{} brick {} level {} @0x{:x}", s.name, id, level, l.mesh.offset);
        NAVE_ASSIGN_OR_RETURN(std::string bytes,
                              s.ReadSection(id, fmt::format("level {} mesh", level), l.mesh));
        NAVE_ASSIGN_OR_RETURN(BrickMesh mesh, codec::DecodeMeshSection(bytes, s.header.grid,
                                                                       s.materials.size(), what));
        NAVE_RETURN_IF_ERROR(CheckCounts(mesh, what, "levels table", l.triangle_count,
                                         l.vertex_count, l.has_normals, l.has_uvs));
        return mesh;
    }
    const std::string what = fmt::format("{} brick {} @0x{:x}", s.name, id, info.mesh.offset);
    if (info.side.length > 0) {
        // Format 1.0 defines no side-section content; verify it so corruption never passes
        // silently.
        NAVE_ASSIGN_OR_RETURN(std::string side, s.ReadSection(id, "side", info.side));
        NAVE_RETURN_IF_ERROR(codec::DecompressSideSection(side, what).status());
    }
    NAVE_ASSIGN_OR_RETURN(std::string bytes, s.ReadSection(id, "mesh", info.mesh));
    NAVE_ASSIGN_OR_RETURN(BrickMesh mesh,
                          codec::DecodeMeshSection(bytes, s.header.grid, s.materials.size(), what));
    NAVE_RETURN_IF_ERROR(CheckCounts(mesh, what, "directory", info.triangle_count,
                                     info.vertex_count, info.has_normals, info.has_uvs));
    return mesh;
}

StatusOr<std::vector<std::byte>> Store::ReadBrickMedium(uint32_t id) const {
    const Impl& s = *impl_;
    NAVE_ASSIGN_OR_RETURN(const BrickInfo* brick, s.Brick(id));
    const SectionInfo& section = brick->medium.grid;
    if (section.length == 0) {
        return NotFoundError("{}: brick {} holds no piece of a medium{}", s.name, id,
                             s.header.medium_grid.empty() ? " (the store has none)" : "");
    }
    std::vector<std::byte> bytes(section.length);
    NAVE_RETURN_IF_ERROR(s.ReadSectionInto(id, "medium", section, bytes.data()));
    return bytes;
}

StatusOr<OccupancyGrid> Store::ReadBrickOccupancy(uint32_t id) const {
    const Impl& s = *impl_;
    NAVE_ASSIGN_OR_RETURN(const BrickInfo* brick, s.Brick(id));
    const SectionInfo& section = brick->occupancy;
    if (section.length == 0) return NotFoundError("{}: brick {} has no occupancy grid", s.name, id);
    NAVE_ASSIGN_OR_RETURN(std::string bytes, s.ReadSection(id, "occupancy", section));
    return OccupancyGrid::Decode(
        bytes, fmt::format("{} brick {} occupancy @0x{:x}", s.name, id, section.offset));
}

Status Store::VerifyBrick(uint32_t id) const {
    NAVE_ASSIGN_OR_RETURN(BrickMesh mesh, ReadBrick(id));
    const BrickInfo& info = impl_->bricks[id];
    if (info.medium.grid.length > 0) NAVE_RETURN_IF_ERROR(ReadBrickMedium(id).status());
    if (info.occupancy.length > 0) NAVE_RETURN_IF_ERROR(ReadBrickOccupancy(id).status());
    Bounds3f box;
    for (const Vec3f& p : mesh.positions) box.Extend(p);
    if (mesh.TriangleCount() > 0 && !(box == info.geometry_bounds)) {
        return DataLossError("{} brick {} @0x{:x}: decoded geometry box {} != directory's {}",
                             impl_->name, id, info.mesh.offset, fmt::streamed(box),
                             fmt::streamed(info.geometry_bounds));
    }
    // A level's vertices are vertices of the brick (edge collapse moves none), snapped to the same
    // grid or (3.2) a coarser one, which moves them by less than the level's error: its box lies
    // inside the brick's grown by that error.
    for (uint32_t k = 1; k <= info.levels.size(); ++k) {
        NAVE_ASSIGN_OR_RETURN(BrickMesh level, ReadBrick(id, k));
        Bounds3f level_box;
        for (const Vec3f& p : level.positions) level_box.Extend(p);
        const float error = info.levels[k - 1].error;
        const Bounds3f allowed(info.geometry_bounds.min - Vec3f(error, error, error),
                               info.geometry_bounds.max + Vec3f(error, error, error));
        if (!allowed.Contains(level_box.min) || !allowed.Contains(level_box.max)) {
            return DataLossError(
                "{} brick {} level {} @0x{:x}: decoded geometry box {} lies outside the brick's {} "
                "grown by the level's error {}",
                impl_->name, id, k, info.levels[k - 1].mesh.offset, fmt::streamed(level_box),
                fmt::streamed(info.geometry_bounds), error);
        }
    }
    return Status::Ok();
}

}  // namespace nave::store
