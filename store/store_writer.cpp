#include "store/store_writer.h"

#include <fmt/ostream.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>

#include "src/core/file.h"
#include "src/core/hash.h"
#include "store/brick_codec.h"
#include "store/store_format.h"

namespace nave::store {

Status ValidateBrickMesh(const BrickMesh& mesh, size_t material_count) {
    if (mesh.indices.size() % 3 != 0) {
        return InvalidArgumentError("brick mesh has {} indices, not a multiple of 3",
                                    mesh.indices.size());
    }
    const size_t triangles = mesh.TriangleCount();
    const size_t vertices = mesh.VertexCount();
    if (vertices > size_t(0xffffffffu)) {
        return InvalidArgumentError("brick mesh has {} vertices, more than 2^32 - 1", vertices);
    }
    if (mesh.material_ids.size() != triangles) {
        return InvalidArgumentError("brick mesh has {} material ids for {} triangles",
                                    mesh.material_ids.size(), triangles);
    }
    if (!mesh.normals.empty() && mesh.normals.size() != vertices) {
        return InvalidArgumentError(
            "brick mesh has {} normals for {} vertices (expected none or one each)",
            mesh.normals.size(), vertices);
    }
    if (!mesh.uvs.empty() && mesh.uvs.size() != vertices) {
        return InvalidArgumentError(
            "brick mesh has {} texture coordinates for {} vertices (expected none or one "
            "each)",
            mesh.uvs.size(), vertices);
    }
    for (size_t i = 0; i < mesh.indices.size(); ++i) {
        if (mesh.indices[i] >= vertices) {
            return InvalidArgumentError(
                "brick mesh triangle {} corner {}: index {} out of range [0, {})", i / 3, i % 3,
                mesh.indices[i], vertices);
        }
    }
    for (size_t t = 0; t < triangles; ++t) {
        if (mesh.material_ids[t] >= material_count) {
            return InvalidArgumentError(
                "brick mesh triangle {}: material id {} out of range [0, {})", t,
                mesh.material_ids[t], material_count);
        }
    }
    for (size_t v = 0; v < vertices; ++v) {
        if (!IsFinite(mesh.positions[v])) {
            return InvalidArgumentError("brick mesh vertex {}: position {} is not finite", v,
                                        fmt::streamed(mesh.positions[v]));
        }
    }
    for (size_t v = 0; v < mesh.normals.size(); ++v) {
        const Vec3f& n = mesh.normals[v];
        const float len = Length(n);
        // Normals are normalized before encoding; a zero or non-finite one has no direction to
        // keep.
        if (!IsFinite(n) || !(len > 1e-12f) || !std::isfinite(len)) {
            return InvalidArgumentError(
                "brick mesh vertex {}: normal {} has no direction (length {})", v, fmt::streamed(n),
                len);
        }
    }
    for (size_t v = 0; v < mesh.uvs.size(); ++v) {
        if (!std::isfinite(mesh.uvs[v][0]) || !std::isfinite(mesh.uvs[v][1])) {
            return InvalidArgumentError(
                "brick mesh vertex {}: texture coordinates ({}, {}) are not finite", v,
                mesh.uvs[v][0], mesh.uvs[v][1]);
        }
    }
    return Status::Ok();
}

StatusOr<EncodedBrick> EncodeBrick(const BrickMesh& mesh, const Bounds3f& cell,
                                   const GlobalGrid& grid, const EncodeOptions& options) {
    // Material ids are checked against the table when the store is finished (Finish knows the
    // table).
    NAVE_RETURN_IF_ERROR(ValidateBrickMesh(mesh, size_t(0x7fffffff) + 1));
    NAVE_ASSIGN_OR_RETURN(codec::EncodedMesh encoded,
                          codec::EncodeMeshSection(mesh, grid, options, cell));
    EncodedBrick brick;
    brick.mesh_bytes = std::move(encoded.bytes);
    brick.cell = cell;
    brick.geometry_bounds = encoded.geometry_bounds;
    brick.triangle_count = encoded.triangle_count;
    brick.vertex_count = encoded.vertex_count;
    brick.decoded_bytes = encoded.decoded_bytes;
    brick.has_normals = encoded.has_normals;
    brick.has_uvs = encoded.has_uvs;
    brick.max_material_id = encoded.max_material_id;
    brick.dropped_triangle_count = encoded.dropped_triangle_count;
    brick.occupancy_bytes = std::move(encoded.occupancy);
    if (options.levels.relative_errors.empty()) return brick;
    NAVE_RETURN_IF_ERROR(ValidateLevelOptions(options.levels));

    const auto start = std::chrono::steady_clock::now();
    // The levels simplify the brick as it decodes: snapped to the grid, and with the vertices
    // Draco splits where the surface is not a manifold (parts touching at an edge or a corner),
    // which meshoptimizer would otherwise lock and keep. The verification decoded it already when
    // options.verify asked.
    if (!encoded.decoded) {
        NAVE_ASSIGN_OR_RETURN(
            encoded.decoded,
            codec::DecodeMeshSection(brick.mesh_bytes, grid, uint64_t(codec::kMaxMaterialId) + 1,
                                     "the brick just encoded"));
    }
    std::vector<BrickLevel> levels = MakeBrickLevels(*encoded.decoded, options.levels, &cell);
    brick.simplify_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EncodeOptions level_options = options;
    level_options.draco_speed = options.levels.draco_speed;
    for (size_t k = 0; k < levels.size(); ++k) {
        const uint32_t shift =
            LevelGridShift(levels[k].mesh, levels[k].error, grid, options.levels);
        auto level = codec::EncodeMeshSection(levels[k].mesh, grid, level_options, cell, shift);
        if (!level.ok()) return level.status().WithContext(fmt::format("level {}", k + 1));
        // Every triangle collapsed on the grid: this level and the coarser ones have nothing to
        // show.
        if (level->triangle_count == 0) break;
        EncodedLevel& out = brick.levels.emplace_back();
        out.mesh_bytes = std::move(level->bytes);
        // Snapped to a coarser grid, the level lies that much farther from the full surface.
        out.error =
            float(double(levels[k].error) + (shift > 0 ? GridSnapDistance(grid, shift) : 0));
        // Errors grow from level to level (the reader checks): a finer level's snap may have
        // raised its error past this one's.
        if (brick.levels.size() > 1) {
            const float finer = brick.levels[brick.levels.size() - 2].error;
            if (!(out.error > finer))
                out.error = std::nextafter(finer, std::numeric_limits<float>::infinity());
        }
        out.triangle_count = level->triangle_count;
        out.vertex_count = level->vertex_count;
        out.decoded_bytes = level->decoded_bytes;
        out.has_normals = level->has_normals;
        out.has_uvs = level->has_uvs;
        out.max_material_id = level->max_material_id;
    }
    return brick;
}

EncodedBrick EmptyBrick(const Bounds3f& cell) {
    EncodedBrick brick;
    brick.mesh_bytes.assign(codec::kMeshPrefixBytes, '\0');
    brick.cell = cell;
    return brick;
}

namespace {

Status WriteTablesAndCommit(AtomicFile& file, format::RawHeader& h,
                            const StoreProvenance& provenance,
                            const std::vector<format::RawBrickEntry>& entries,
                            const BrickTree& tree, const std::vector<MaterialRecord>& materials,
                            const std::string& medium_grid) {
    auto write_table = [&](const std::string& bytes, SectionInfo* ref) -> Status {
        *ref = {file.size(), bytes.size(), Checksum64(bytes.data(), bytes.size())};
        return file.Write(bytes);
    };
    NAVE_RETURN_IF_ERROR(write_table(format::EncodeProvenance(provenance), &h.provenance));
    NAVE_RETURN_IF_ERROR(write_table(format::EncodeDirectory(entries), &h.directory));
    NAVE_RETURN_IF_ERROR(write_table(format::EncodeTree(tree), &h.tree));
    NAVE_RETURN_IF_ERROR(write_table(format::EncodeMaterials(materials), &h.materials));
    // A store without levels has no levels table (its header's section stays zero, as in 3.0).
    const bool any_levels = std::any_of(entries.begin(), entries.end(),
                                        [](const auto& e) { return !e.info.levels.empty(); });
    if (any_levels) NAVE_RETURN_IF_ERROR(write_table(format::EncodeLevels(entries), &h.levels));
    // Likewise a store without a medium has no medium table (as in 3.2).
    if (!medium_grid.empty())
        NAVE_RETURN_IF_ERROR(write_table(format::EncodeMedium(medium_grid, entries), &h.medium));
    // And one without occupancy grids none of those.
    const bool any_occupancy = std::any_of(
        entries.begin(), entries.end(), [](const auto& e) { return e.info.occupancy.length > 0; });
    if (any_occupancy)
        NAVE_RETURN_IF_ERROR(write_table(format::EncodeOccupancy(entries), &h.occupancy));
    h.file_bytes = file.size();
    const std::string header = format::EncodeHeader(h);
    NAVE_RETURN_IF_ERROR(file.WriteAt(0, header.data(), header.size()));
    return file.Commit();
}

}  // namespace

struct StoreWriter::Impl {
    AtomicFile file;
    GlobalGrid grid;
    StoreProvenance provenance;
    std::vector<format::RawBrickEntry> entries;
    std::vector<uint32_t> max_material_ids;  // per brick, 0 for bricks without triangles
    bool finished = false;
    std::string medium_grid;  // SetMediumGrid's name; empty: no medium table
};

StoreWriter::StoreWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
StoreWriter::~StoreWriter() = default;  // AtomicFile removes the temporary file unless committed

StatusOr<std::unique_ptr<StoreWriter>> StoreWriter::Create(const std::filesystem::path& path,
                                                           const GlobalGrid& grid,
                                                           StoreProvenance provenance) {
    if (!(grid.step > 0) || !std::isfinite(grid.step) || !IsFinite(grid.origin)) {
        return InvalidArgumentError(
            "{}: invalid grid: origin {}, step {} (the step must be finite and > 0)", path.string(),
            fmt::streamed(grid.origin), grid.step);
    }
    NAVE_ASSIGN_OR_RETURN(AtomicFile file, AtomicFile::Create(path));
    // A zero header: until Finish() patches it, the file has no magic and can never open as a
    // store.
    const std::string zeros(format::kCurrentHeaderBytes, '\0');
    NAVE_RETURN_IF_ERROR(file.Write(zeros));
    auto impl = std::make_unique<Impl>(
        Impl{std::move(file), grid, std::move(provenance), {}, {}, false, {}});
    return std::unique_ptr<StoreWriter>(new StoreWriter(std::move(impl)));
}

uint64_t StoreWriter::bytes_written() const { return impl_->file.size(); }

StatusOr<uint32_t> StoreWriter::Append(const EncodedBrick& brick) {
    NAVE_CHECK(!impl_->finished) << "StoreWriter::Append after Finish";
    const std::string& name = impl_->file.path().string();
    const uint32_t id = uint32_t(impl_->entries.size());
    if (id == kNoBrick)
        return InvalidArgumentError("{}: too many bricks (at most {})", name, kNoBrick);
    if (brick.mesh_bytes.size() < codec::kMeshPrefixBytes) {
        return InvalidArgumentError(
            "{}: brick {} has a mesh section of {} bytes; use EncodeBrick to make one", name, id,
            brick.mesh_bytes.size());
    }
    if (brick.decoded_bytes != BrickMesh::BytesFor(brick.vertex_count, brick.triangle_count,
                                                   brick.has_normals, brick.has_uvs)) {
        return InvalidArgumentError(
            "{}: brick {}: decoded_bytes {} does not match its counts; use EncodeBrick", name, id,
            brick.decoded_bytes);
    }
    for (size_t k = 0; k < brick.levels.size(); ++k) {
        const EncodedLevel& l = brick.levels[k];
        const float finer_error = k == 0 ? 0.f : brick.levels[k - 1].error;
        const uint64_t finer_triangles =
            k == 0 ? brick.triangle_count : brick.levels[k - 1].triangle_count;
        if (l.mesh_bytes.size() < codec::kMeshPrefixBytes ||
            l.decoded_bytes !=
                BrickMesh::BytesFor(l.vertex_count, l.triangle_count, l.has_normals, l.has_uvs)) {
            return InvalidArgumentError(
                "{}: brick {} level {}: a mesh section of {} bytes, or decoded_bytes {} that does "
                "not match its counts; use EncodeBrick",
                name, id, k + 1, l.mesh_bytes.size(), l.decoded_bytes);
        }
        if (!std::isfinite(l.error) || l.error < 0 || (k > 0 && !(l.error > finer_error))) {
            return InvalidArgumentError(
                "{}: brick {} level {}: error {} (expected finite, >= 0 and larger than level "
                "{}'s {})",
                name, id, k + 1, l.error, k, finer_error);
        }
        if (l.triangle_count == 0 || l.triangle_count > finer_triangles) {
            return InvalidArgumentError(
                "{}: brick {} level {}: {} triangles (expected 1 to level {}'s {})", name, id,
                k + 1, l.triangle_count, k, finer_triangles);
        }
    }
    if (brick.levels.size() > format::kMaxLevels) {
        return InvalidArgumentError("{}: brick {} has {} levels (at most {})", name, id,
                                    brick.levels.size(), format::kMaxLevels);
    }
    format::RawBrickEntry e;
    e.info.id = id;
    e.info.cell = brick.cell;
    e.info.geometry_bounds = brick.geometry_bounds;
    e.info.triangle_count = brick.triangle_count;
    e.info.vertex_count = brick.vertex_count;
    e.info.decoded_bytes = brick.decoded_bytes;
    e.info.has_normals = brick.has_normals;
    e.info.has_uvs = brick.has_uvs;
    e.flags = (brick.has_normals ? format::kBrickHasNormals : 0) |
              (brick.has_uvs ? format::kBrickHasUvs : 0);
    e.info.mesh = {impl_->file.size(), brick.mesh_bytes.size(),
                   Checksum64(brick.mesh_bytes.data(), brick.mesh_bytes.size())};
    NAVE_RETURN_IF_ERROR(impl_->file.Write(brick.mesh_bytes));
    uint32_t max_material_id = brick.max_material_id;
    for (const EncodedLevel& l : brick.levels) {
        LevelInfo& level = e.info.levels.emplace_back();
        level.error = l.error;
        level.triangle_count = l.triangle_count;
        level.vertex_count = l.vertex_count;
        level.decoded_bytes = l.decoded_bytes;
        level.has_normals = l.has_normals;
        level.has_uvs = l.has_uvs;
        level.mesh = {impl_->file.size(), l.mesh_bytes.size(),
                      Checksum64(l.mesh_bytes.data(), l.mesh_bytes.size())};
        NAVE_RETURN_IF_ERROR(impl_->file.Write(l.mesh_bytes));
        max_material_id = std::max(max_material_id, l.max_material_id);
    }
    if (!brick.side_bytes.empty()) {
        e.info.side = {impl_->file.size(), brick.side_bytes.size(),
                       Checksum64(brick.side_bytes.data(), brick.side_bytes.size())};
        NAVE_RETURN_IF_ERROR(impl_->file.Write(brick.side_bytes));
    }
    if (!brick.occupancy_bytes.empty()) {
        e.info.occupancy = {impl_->file.size(), brick.occupancy_bytes.size(),
                            Checksum64(brick.occupancy_bytes.data(), brick.occupancy_bytes.size())};
        NAVE_RETURN_IF_ERROR(impl_->file.Write(brick.occupancy_bytes));
    }
    impl_->entries.push_back(e);
    impl_->max_material_ids.push_back(brick.triangle_count > 0 ? max_material_id : 0);
    return id;
}

Status StoreWriter::SetMediumGrid(const std::string& grid) {
    NAVE_CHECK(!impl_->finished) << "StoreWriter::SetMediumGrid after Finish";
    const std::string& name = impl_->file.path().string();
    if (grid.empty()) return InvalidArgumentError("{}: the medium's grid needs a name", name);
    if (!impl_->medium_grid.empty()) {
        return InvalidArgumentError("{}: the medium's grid is '{}' already, not '{}'", name,
                                    impl_->medium_grid, grid);
    }
    impl_->medium_grid = grid;
    return Status::Ok();
}

Status StoreWriter::AppendMedium(uint32_t id, const EncodedMedium& medium) {
    NAVE_CHECK(!impl_->finished) << "StoreWriter::AppendMedium after Finish";
    Impl& w = *impl_;
    const std::string& name = w.file.path().string();
    if (w.medium_grid.empty())
        return InvalidArgumentError("{}: brick {}: a piece of a medium before SetMediumGrid", name,
                                    id);
    if (id >= w.entries.size()) {
        return InvalidArgumentError("{}: brick {} was not appended (there are {} bricks)", name, id,
                                    w.entries.size());
    }
    BrickMediumInfo& info = w.entries[id].info.medium;
    if (info.grid.length > 0)
        return InvalidArgumentError("{}: brick {} has a piece of the medium already", name, id);
    if (medium.grid_bytes.empty() || medium.active_voxels == 0 ||
        !std::isfinite(medium.max_density) || medium.max_density < 0) {
        return InvalidArgumentError(
            "{}: brick {}: a piece of the medium of {} bytes, {} voxels and majorant {} (expected "
            "bytes, voxels and a finite majorant >= 0)",
            name, id, medium.grid_bytes.size(), medium.active_voxels, medium.max_density);
    }
    const SectionInfo section = {w.file.size(), medium.grid_bytes.size(),
                                 Checksum64(medium.grid_bytes.data(), medium.grid_bytes.size())};
    NAVE_RETURN_IF_ERROR(w.file.Write(medium.grid_bytes.data(), medium.grid_bytes.size()));
    info.grid = section;
    info.active_voxels = medium.active_voxels;
    info.max_density = medium.max_density;
    info.decoded_bytes = medium.decoded_bytes;
    return Status::Ok();
}

Status StoreWriter::Finish(const std::vector<MaterialRecord>& materials, const BrickTree& tree,
                           uint64_t source_triangle_count) {
    NAVE_CHECK(!impl_->finished) << "StoreWriter::Finish called twice";
    Impl& w = *impl_;
    const std::string name = w.file.path().string();
    const uint32_t brick_count = uint32_t(w.entries.size());

    // Check everything before writing a byte of the tables, so a refused Finish can be fixed and
    // retried.
    if (materials.size() > 0xffffffffu) return InvalidArgumentError("{}: too many materials", name);
    std::set<std::string> names;
    for (size_t i = 0; i < materials.size(); ++i) {
        if (!names.insert(materials[i].name).second) {
            return InvalidArgumentError("{}: material {} \"{}\": the name is used twice", name, i,
                                        materials[i].name);
        }
    }
    for (uint32_t b = 0; b < brick_count; ++b) {
        if (w.entries[b].info.triangle_count > 0 && w.max_material_ids[b] >= materials.size()) {
            return InvalidArgumentError(
                "{}: brick {} uses material {} but the material table has {} entries", name, b,
                w.max_material_ids[b], materials.size());
        }
    }
    if (tree.nodes().empty()) return InvalidArgumentError("{}: the brick tree has no nodes", name);
    if (!IsFinite(tree.bounds().min) || !IsFinite(tree.bounds().max) || tree.bounds().Empty()) {
        return InvalidArgumentError("{}: the brick tree's bounds {} are not a finite box", name,
                                    fmt::streamed(tree.bounds()));
    }
    Status valid = tree.Validate(brick_count);
    if (!valid.ok()) return Status(StatusCode::kInvalidArgument, name + ": " + valid.message());
    std::vector<uint8_t> in_tree(brick_count, 0);
    for (const BrickTreeNode& n : tree.nodes()) {
        if (n.IsLeaf() && n.brick != kNoBrick) in_tree[n.brick] = 1;
    }
    const std::vector<Bounds3f> cells = tree.BrickCells(brick_count);
    for (uint32_t b = 0; b < brick_count; ++b) {
        if (!in_tree[b])
            return InvalidArgumentError("{}: brick {} is in no leaf of the brick tree", name, b);
        // The tree is the authority on cells; a brick appended without a cell takes the tree's.
        const Bounds3f& cell = w.entries[b].info.cell;
        if (!cell.Empty() && !(cell == cells[b])) {
            return InvalidArgumentError(
                "{}: brick {} was appended with cell {} but its tree leaf's cell is {}", name, b,
                fmt::streamed(cell), fmt::streamed(cells[b]));
        }
    }
    for (uint32_t b = 0; b < brick_count; ++b) w.entries[b].info.cell = cells[b];

    format::RawHeader h;
    h.grid = w.grid;
    h.brick_count = brick_count;
    h.material_count = uint32_t(materials.size());
    h.tree_node_count = uint32_t(tree.nodes().size());
    h.source_triangle_count = source_triangle_count;
    for (const format::RawBrickEntry& e : w.entries) {
        h.triangle_count += e.info.triangle_count;
        if (e.info.triangle_count > 0) h.bounds.Extend(e.info.geometry_bounds);
    }

    // From here on a failure abandons the file: tables after the payloads, each with its checksum,
    // then the header at offset 0, then fsync and rename.
    w.finished = true;
    Status written =
        WriteTablesAndCommit(w.file, h, w.provenance, w.entries, tree, materials, w.medium_grid);
    if (!written.ok()) w.file.Abandon();
    return written;
}

}  // namespace nave::store
