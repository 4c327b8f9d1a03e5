#include "store/store_format.h"

#include <fmt/ostream.h>

#include <algorithm>
#include <cmath>

#include "src/core/hash.h"
#include "store/brick_mesh.h"

namespace nave::store::format {
namespace {

// Upper bounds that keep a corrupt count from turning into a huge allocation before a checksum or
// size check can catch it.
constexpr uint32_t kMaxStringBytes = 1u << 24;
constexpr uint32_t kMaxHeaderBytes = 1u << 16;

void PutSection(ByteWriter& w, const SectionInfo& s) {
    w.Put(s.offset);
    w.Put(s.length);
    w.Put(s.checksum);
}

Status GetSection(ByteReader& r, SectionInfo* s) {
    NAVE_RETURN_IF_ERROR(r.Get(&s->offset));
    NAVE_RETURN_IF_ERROR(r.Get(&s->length));
    return r.Get(&s->checksum);
}

bool FiniteBounds(const Bounds3f& b) { return IsFinite(b.min) && IsFinite(b.max); }

/// Whether section `s` lies in the payload area, from the header's end to the first table (the
/// tables follow the payloads).
bool InPayloadArea(const SectionInfo& s, const RawHeader& h) {
    const uint64_t end = h.provenance.offset;
    return s.offset >= h.header_bytes && s.offset <= end && s.length <= end - s.offset;
}

/// The error for section `s` outside the payload area, `prefix` naming the store, the brick, the
/// entry and the section ("abbey.nave brick 3 medium @0x1c0: ").
Status OutsidePayloadArea(const SectionInfo& s, const RawHeader& h, const std::string& prefix) {
    return DataLossError("{}section [0x{:x}, +{}) lies outside the payload area [0x{:x}, 0x{:x})",
                         prefix, s.offset, s.length, h.header_bytes, h.provenance.offset);
}

/// Checks that the entries after a per-brick table's prefix fill the rest of it exactly.
Status CheckEntriesFill(const ByteReader& r, const std::string& name, const char* table,
                        uint32_t brick_count, uint32_t entry_bytes) {
    if (r.remaining() == uint64_t(brick_count) * entry_bytes) return Status::Ok();
    return DataLossError("{} {} @0x{:x}: {} bytes of entries, expected {} bricks x {} = {}", name,
                         table, r.file_pos(), r.remaining(), brick_count, entry_bytes,
                         uint64_t(brick_count) * entry_bytes);
}

/// Reads the prefix of a table with an entry per brick (u32 entry size, u32 brick count) and checks
/// both: the entry size within [`min_entry`, kMaxHeaderBytes], the count the header's and
/// `entries`'. Errors name the store, the table and its offset. Returns the entry size.
StatusOr<uint32_t> ReadBrickTablePrefix(ByteReader& r, const RawHeader& h, const std::string& name,
                                        const char* table, uint64_t offset, uint32_t min_entry,
                                        size_t entries) {
    uint32_t entry_bytes = 0, brick_count = 0;
    NAVE_RETURN_IF_ERROR(r.Get(&entry_bytes));
    NAVE_RETURN_IF_ERROR(r.Get(&brick_count));
    if (entry_bytes < min_entry || entry_bytes > kMaxHeaderBytes) {
        return DataLossError("{} {} @0x{:x}: entry size {} out of range [{}, {}]", name, table,
                             offset, entry_bytes, min_entry, kMaxHeaderBytes);
    }
    if (brick_count != h.brick_count || brick_count != entries) {
        return DataLossError("{} {} @0x{:x}: the table has {} bricks, the header says {}", name,
                             table, offset, brick_count, h.brick_count);
    }
    return entry_bytes;
}

}  // namespace

void ByteWriter::PutBounds(const Bounds3f& b) {
    Put(b.min.x), Put(b.min.y), Put(b.min.z);
    Put(b.max.x), Put(b.max.y), Put(b.max.z);
}

void ByteWriter::PutString(std::string_view s) {
    NAVE_CHECK_LT(s.size(), size_t(kMaxStringBytes)) << "string too long for the store format";
    Put(uint32_t(s.size()));
    bytes_.append(s);
}

Status ByteReader::Need(size_t n) const {
    if (n > bytes_.size() - pos_) {
        return DataLossError("{} @0x{:x}: need {} bytes but only {} remain in the table", what_,
                             file_pos(), n, bytes_.size() - pos_);
    }
    return Status::Ok();
}

Status ByteReader::GetBounds(Bounds3f* b) {
    for (int a = 0; a < 3; ++a) NAVE_RETURN_IF_ERROR(Get(&b->min[a]));
    for (int a = 0; a < 3; ++a) NAVE_RETURN_IF_ERROR(Get(&b->max[a]));
    return Status::Ok();
}

Status ByteReader::GetString(std::string* s) {
    uint32_t n = 0;
    const uint64_t at = file_pos();
    NAVE_RETURN_IF_ERROR(Get(&n));
    if (n > kMaxStringBytes) {
        return DataLossError("{} @0x{:x}: string length {} exceeds the limit {}", what_, at, n,
                             kMaxStringBytes);
    }
    NAVE_RETURN_IF_ERROR(Need(n));
    s->assign(bytes_.data() + pos_, n);
    pos_ += n;
    return Status::Ok();
}

Status ByteReader::Skip(size_t n) {
    NAVE_RETURN_IF_ERROR(Need(n));
    pos_ += n;
    return Status::Ok();
}

// ---- header

std::string EncodeHeader(const RawHeader& h) {
    ByteWriter w;
    w.bytes().append(kMagic, sizeof(kMagic));
    w.Put(h.major);
    w.Put(h.minor);
    w.Put(h.header_bytes);
    w.Put(h.file_bytes);
    w.Put(h.grid.origin.x), w.Put(h.grid.origin.y), w.Put(h.grid.origin.z);
    w.Put(h.grid.step);
    w.PutBounds(h.bounds);
    w.Put(h.triangle_count);
    w.Put(h.source_triangle_count);
    w.Put(h.brick_count);
    w.Put(h.material_count);
    w.Put(h.tree_node_count);
    w.Put(h.directory_entry_bytes);
    w.Put(h.tree_node_bytes);
    w.Put(uint32_t(0));  // reserved flags
    PutSection(w, h.provenance);
    PutSection(w, h.directory);
    PutSection(w, h.tree);
    PutSection(w, h.materials);
    PutSection(w, h.levels);  // 3.1
    // 3.3; a header too small for it (one relabelled older, in tests) ends before it.
    if (h.header_bytes >= kMediumHeaderBytes) PutSection(w, h.medium);
    if (h.header_bytes >= kOccupancyHeaderBytes) PutSection(w, h.occupancy);  // 3.4
    NAVE_CHECK_LE(w.size(), size_t(h.header_bytes - 8));
    w.PutZeros(h.header_bytes - 8 - w.size());
    w.Put(Checksum64(w.bytes().data(), w.size()));
    NAVE_CHECK_EQ(w.size(), size_t(h.header_bytes));
    return std::move(w.bytes());
}

StatusOr<RawHeader> DecodeHeader(std::string_view bytes, const std::string& name,
                                 uint64_t file_bytes) {
    // Magic and version come first and are checked before anything else is trusted: a future major
    // version may lay out everything after the 16-byte prefix differently.
    if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
        const size_t n = std::min(bytes.size(), sizeof(kMagic));
        if (n < sizeof(kMagic) && std::memcmp(bytes.data(), kMagic, n) == 0) {
            return DataLossError("{}: truncated: {} bytes, too short for a store header ({} bytes)",
                                 name, file_bytes, kHeaderBytes);
        }
        if (n == sizeof(kMagic) &&
            std::all_of(bytes.begin(), bytes.begin() + n, [](char c) { return c == 0; })) {
            // The writer's placeholder: the header is written last, so this store was never
            // finished.
            return DataLossError("{}: the header is all zeros: the store's writing never finished",
                                 name);
        }
        std::string found;
        for (size_t i = 0; i < n; ++i) {
            const unsigned char c = static_cast<unsigned char>(bytes[i]);
            found +=
                (c >= 32 && c < 127) ? fmt::format("{}", char(c)) : fmt::format("\\x{:02x}", c);
        }
        return UnsupportedError("{}: not a nave store: magic \"{}\" != \"NAVESTOR\"", name, found);
    }
    if (bytes.size() < kHeaderPrefixBytes) {
        return DataLossError("{}: truncated: {} bytes, too short for a store header ({} bytes)",
                             name, file_bytes, kHeaderBytes);
    }
    ByteReader r(bytes, name + " header", 0);
    NAVE_RETURN_IF_ERROR(r.Skip(sizeof(kMagic)));
    RawHeader h;
    NAVE_RETURN_IF_ERROR(r.Get(&h.major));
    NAVE_RETURN_IF_ERROR(r.Get(&h.minor));
    if (h.major < kOldestReadableMajor || h.major > kFormatMajor) {
        return UnsupportedError(
            "{}: store format version {}.{} cannot be read by this nave, which reads versions "
            "{}.x to {}.x (up to {}.{}); "
            "{}",
            name, h.major, h.minor, kOldestReadableMajor, kFormatMajor, kFormatMajor, kFormatMinor,
            h.major > kFormatMajor ? "use a newer nave"
                                   : "re-create the store with `nave preprocess`");
    }
    NAVE_RETURN_IF_ERROR(r.Get(&h.header_bytes));
    if (h.header_bytes < kHeaderBytes || h.header_bytes > kMaxHeaderBytes) {
        return DataLossError("{} @0x{:x}: header size {} out of range [{}, {}]", name, 12,
                             h.header_bytes, kHeaderBytes, kMaxHeaderBytes);
    }
    if (bytes.size() < h.header_bytes) {
        return DataLossError("{}: truncated: {} bytes, too short for its {}-byte header", name,
                             file_bytes, h.header_bytes);
    }
    uint64_t stored_checksum = 0;
    std::memcpy(&stored_checksum, bytes.data() + h.header_bytes - 8, 8);
    const uint64_t checksum = Checksum64(bytes.data(), h.header_bytes - 8);
    if (checksum != stored_checksum) {
        return DataLossError(
            "{} header @0x0: checksum {} != stored {} (the header is corrupt, or the file was "
            "not completely written)",
            name, ChecksumHex(checksum), ChecksumHex(stored_checksum));
    }
    NAVE_RETURN_IF_ERROR(r.Get(&h.file_bytes));
    NAVE_RETURN_IF_ERROR(r.Get(&h.grid.origin.x));
    NAVE_RETURN_IF_ERROR(r.Get(&h.grid.origin.y));
    NAVE_RETURN_IF_ERROR(r.Get(&h.grid.origin.z));
    NAVE_RETURN_IF_ERROR(r.Get(&h.grid.step));
    NAVE_RETURN_IF_ERROR(r.GetBounds(&h.bounds));
    NAVE_RETURN_IF_ERROR(r.Get(&h.triangle_count));
    NAVE_RETURN_IF_ERROR(r.Get(&h.source_triangle_count));
    NAVE_RETURN_IF_ERROR(r.Get(&h.brick_count));
    NAVE_RETURN_IF_ERROR(r.Get(&h.material_count));
    NAVE_RETURN_IF_ERROR(r.Get(&h.tree_node_count));
    NAVE_RETURN_IF_ERROR(r.Get(&h.directory_entry_bytes));
    NAVE_RETURN_IF_ERROR(r.Get(&h.tree_node_bytes));
    uint32_t reserved = 0;
    NAVE_RETURN_IF_ERROR(r.Get(&reserved));
    NAVE_RETURN_IF_ERROR(GetSection(r, &h.provenance));
    NAVE_RETURN_IF_ERROR(GetSection(r, &h.directory));
    NAVE_RETURN_IF_ERROR(GetSection(r, &h.tree));
    NAVE_RETURN_IF_ERROR(GetSection(r, &h.materials));
    // Before 3.1 these bytes are the zero padding: no levels table.
    if (h.major > 3 || (h.major == 3 && h.minor >= 1))
        NAVE_RETURN_IF_ERROR(GetSection(r, &h.levels));
    // Before 3.3 the header may end here: no medium table.
    if (h.major > 3 || (h.major == 3 && h.minor >= 3)) {
        if (h.header_bytes < kMediumHeaderBytes) {
            return DataLossError(
                "{} @0x{:x}: header size {}, too small for version {}.{} (at "
                "least {})",
                name, 12, h.header_bytes, h.major, h.minor, kMediumHeaderBytes);
        }
        NAVE_RETURN_IF_ERROR(GetSection(r, &h.medium));
    }
    // Before 3.4 the header may end here: no occupancy table.
    if (h.major > 3 || (h.major == 3 && h.minor >= 4)) {
        if (h.header_bytes < kOccupancyHeaderBytes) {
            return DataLossError(
                "{} @0x{:x}: header size {}, too small for version {}.{} (at least {})", name, 12,
                h.header_bytes, h.major, h.minor, kOccupancyHeaderBytes);
        }
        NAVE_RETURN_IF_ERROR(GetSection(r, &h.occupancy));
    }

    // The checksum matched, so what follows catches writer bugs and files cut or extended after
    // writing.
    if (h.file_bytes != file_bytes) {
        return DataLossError("{}: the file has {} bytes but its header says {} ({})", name,
                             file_bytes, h.file_bytes,
                             file_bytes < h.file_bytes ? "truncated" : "extra bytes appended");
    }
    if (!(h.grid.step > 0) || !std::isfinite(h.grid.step) || !IsFinite(h.grid.origin)) {
        return DataLossError("{} header: invalid grid (origin {}, step {})", name,
                             fmt::streamed(h.grid.origin), h.grid.step);
    }
    if (h.directory_entry_bytes < kDirectoryEntryBytes ||
        h.directory_entry_bytes > kMaxHeaderBytes) {
        return DataLossError(
            "{} header: directory entry size {} < {} (the minimum for version {}.x)", name,
            h.directory_entry_bytes, kDirectoryEntryBytes, kFormatMajor);
    }
    if (h.tree_node_bytes < kTreeNodeBytes || h.tree_node_bytes > kMaxHeaderBytes) {
        return DataLossError("{} header: tree node size {} < {} (the minimum for version {}.x)",
                             name, h.tree_node_bytes, kTreeNodeBytes, kFormatMajor);
    }
    struct Named {
        const char* what;
        const SectionInfo* ref;
    };
    for (const Named& t :
         {Named{"provenance", &h.provenance}, Named{"directory", &h.directory},
          Named{"tree", &h.tree}, Named{"materials", &h.materials}, Named{"levels", &h.levels},
          Named{"medium", &h.medium}, Named{"occupancy", &h.occupancy}}) {
        // No levels, no medium, or no occupancy grids.
        if ((t.ref == &h.levels || t.ref == &h.medium || t.ref == &h.occupancy) &&
            t.ref->length == 0)
            continue;
        if (t.ref->offset < h.header_bytes || t.ref->offset > file_bytes ||
            t.ref->length > file_bytes - t.ref->offset) {
            return DataLossError(
                "{} header: {} table [0x{:x}, +{}) lies outside the file's data [0x{:x}, 0x{:x})",
                name, t.what, t.ref->offset, t.ref->length, h.header_bytes, file_bytes);
        }
    }
    const uint64_t expected_dir = uint64_t(h.brick_count) * h.directory_entry_bytes;
    if (h.directory.length != expected_dir) {
        return DataLossError("{} header: directory is {} bytes, expected {} bricks x {} = {}", name,
                             h.directory.length, h.brick_count, h.directory_entry_bytes,
                             expected_dir);
    }
    const uint64_t expected_tree = 24 + uint64_t(h.tree_node_count) * h.tree_node_bytes;
    if (h.tree.length != expected_tree) {
        return DataLossError("{} header: tree table is {} bytes, expected 24 + {} nodes x {} = {}",
                             name, h.tree.length, h.tree_node_count, h.tree_node_bytes,
                             expected_tree);
    }
    return h;
}

// ---- provenance

std::string EncodeProvenance(const StoreProvenance& p) {
    ByteWriter w;
    w.Put(uint32_t(p.source_files.size()));
    for (const std::string& f : p.source_files) w.PutString(f);
    w.PutString(p.tool_version);
    w.PutString(p.options);
    return std::move(w.bytes());
}

StatusOr<StoreProvenance> DecodeProvenance(std::string_view bytes, const std::string& name,
                                           uint64_t offset) {
    ByteReader r(bytes, name + " provenance", offset);
    StoreProvenance p;
    uint32_t n = 0;
    NAVE_RETURN_IF_ERROR(r.Get(&n));
    // Each name takes at least its 4-byte length: a count beyond that is corrupt, whatever the
    // checksum said.
    if (n > r.remaining() / 4) {
        return DataLossError("{} @0x{:x}: {} source files cannot fit in {} bytes", r.what(), offset,
                             n, bytes.size());
    }
    p.source_files.resize(n);
    for (std::string& f : p.source_files) NAVE_RETURN_IF_ERROR(r.GetString(&f));
    NAVE_RETURN_IF_ERROR(r.GetString(&p.tool_version));
    NAVE_RETURN_IF_ERROR(r.GetString(&p.options));
    // Bytes beyond these fields belong to a newer minor version and are ignored.
    return p;
}

// ---- directory

std::string EncodeDirectory(const std::vector<RawBrickEntry>& entries) {
    ByteWriter w;
    for (const RawBrickEntry& e : entries) {
        const size_t start = w.size();
        w.Put(e.info.id);
        w.Put(e.flags);
        w.PutBounds(e.info.cell);
        w.PutBounds(e.info.geometry_bounds);
        w.Put(e.info.triangle_count);
        w.Put(e.info.vertex_count);
        w.Put(e.info.decoded_bytes);
        PutSection(w, e.info.mesh);
        PutSection(w, e.info.side);
        NAVE_CHECK_EQ(w.size() - start, size_t(kDirectoryEntryBytes));
    }
    return std::move(w.bytes());
}

StatusOr<std::vector<RawBrickEntry>> DecodeDirectory(std::string_view bytes, const RawHeader& h,
                                                     const std::string& name) {
    std::vector<RawBrickEntry> entries(h.brick_count);
    for (uint32_t i = 0; i < h.brick_count; ++i) {
        const uint64_t entry_offset = h.directory.offset + uint64_t(i) * h.directory_entry_bytes;
        ByteReader r(bytes.substr(size_t(i) * h.directory_entry_bytes, h.directory_entry_bytes),
                     fmt::format("{} directory entry {}", name, i), entry_offset);
        RawBrickEntry& e = entries[i];
        NAVE_RETURN_IF_ERROR(r.Get(&e.info.id));
        NAVE_RETURN_IF_ERROR(r.Get(&e.flags));
        NAVE_RETURN_IF_ERROR(r.GetBounds(&e.info.cell));
        NAVE_RETURN_IF_ERROR(r.GetBounds(&e.info.geometry_bounds));
        NAVE_RETURN_IF_ERROR(r.Get(&e.info.triangle_count));
        NAVE_RETURN_IF_ERROR(r.Get(&e.info.vertex_count));
        NAVE_RETURN_IF_ERROR(r.Get(&e.info.decoded_bytes));
        NAVE_RETURN_IF_ERROR(GetSection(r, &e.info.mesh));
        NAVE_RETURN_IF_ERROR(GetSection(r, &e.info.side));
        e.info.has_normals = (e.flags & kBrickHasNormals) != 0;
        e.info.has_uvs = (e.flags & kBrickHasUvs) != 0;
        if (e.info.id != i) {
            return DataLossError("{} brick {} @0x{:x}: directory entry says id {} (expected {})",
                                 name, i, entry_offset, e.info.id, i);
        }
        for (const auto& [what, s] :
             {std::pair<const char*, const SectionInfo*>{"mesh", &e.info.mesh},
              std::pair<const char*, const SectionInfo*>{"side", &e.info.side}}) {
            if (s->length > 0 && !InPayloadArea(*s, h))
                return OutsidePayloadArea(
                    *s, h, fmt::format("{} brick {} @0x{:x}: {} ", name, i, entry_offset, what));
        }
        if (e.info.mesh.length == 0 && e.info.triangle_count > 0) {
            return DataLossError("{} brick {} @0x{:x}: {} triangles but no mesh section", name, i,
                                 entry_offset, e.info.triangle_count);
        }
        if (!FiniteBounds(e.info.cell)) {
            return DataLossError("{} brick {} @0x{:x}: cell {} is not finite", name, i,
                                 entry_offset, fmt::streamed(e.info.cell));
        }
    }
    return entries;
}

// ---- tree

std::string EncodeTree(const BrickTree& tree) {
    ByteWriter w;
    w.PutBounds(tree.bounds());
    for (const BrickTreeNode& n : tree.nodes()) {
        w.Put(n.axis);
        w.PutZeros(3);
        w.Put(n.split);
        w.Put(n.child[0]);
        w.Put(n.child[1]);
        w.Put(n.brick);
    }
    return std::move(w.bytes());
}

StatusOr<BrickTree> DecodeTree(std::string_view bytes, const RawHeader& h,
                               const std::string& name) {
    ByteReader r(bytes, name + " tree", h.tree.offset);
    Bounds3f bounds;
    NAVE_RETURN_IF_ERROR(r.GetBounds(&bounds));
    if (!FiniteBounds(bounds)) {
        return DataLossError("{} tree @0x{:x}: root bounds {} are not finite", name, h.tree.offset,
                             fmt::streamed(bounds));
    }
    std::vector<BrickTreeNode> nodes(h.tree_node_count);
    for (uint32_t i = 0; i < h.tree_node_count; ++i) {
        const size_t start = r.pos();
        BrickTreeNode& n = nodes[i];
        NAVE_RETURN_IF_ERROR(r.Get(&n.axis));
        NAVE_RETURN_IF_ERROR(r.Skip(3));
        NAVE_RETURN_IF_ERROR(r.Get(&n.split));
        NAVE_RETURN_IF_ERROR(r.Get(&n.child[0]));
        NAVE_RETURN_IF_ERROR(r.Get(&n.child[1]));
        NAVE_RETURN_IF_ERROR(r.Get(&n.brick));
        NAVE_RETURN_IF_ERROR(r.Skip(h.tree_node_bytes - (r.pos() - start)));
    }
    BrickTree tree(bounds, std::move(nodes));
    Status valid = tree.Validate(h.brick_count);
    if (!valid.ok()) return valid.WithContext(fmt::format("{} tree @0x{:x}", name, h.tree.offset));
    return tree;
}

// ---- levels

std::string EncodeLevels(const std::vector<RawBrickEntry>& entries) {
    ByteWriter w;
    w.Put(kLevelEntryBytes);
    w.Put(uint32_t(entries.size()));
    for (const RawBrickEntry& e : entries) {
        w.Put(uint32_t(e.info.levels.size()));
        for (const LevelInfo& l : e.info.levels) {
            const size_t start = w.size();
            w.Put(l.error);
            w.Put(
                uint32_t((l.has_normals ? kBrickHasNormals : 0) | (l.has_uvs ? kBrickHasUvs : 0)));
            w.Put(l.triangle_count);
            w.Put(l.vertex_count);
            w.Put(l.decoded_bytes);
            PutSection(w, l.mesh);
            NAVE_CHECK_EQ(w.size() - start, size_t(kLevelEntryBytes));
        }
    }
    return std::move(w.bytes());
}

Status DecodeLevels(std::string_view bytes, const RawHeader& h, const std::string& name,
                    std::vector<RawBrickEntry>* entries) {
    ByteReader r(bytes, name + " levels", h.levels.offset);
    NAVE_ASSIGN_OR_RETURN(const uint32_t entry_bytes,
                          ReadBrickTablePrefix(r, h, name, "levels", h.levels.offset,
                                               kLevelEntryBytes, entries->size()));
    const uint32_t brick_count = h.brick_count;
    for (uint32_t i = 0; i < brick_count; ++i) {
        BrickInfo& b = (*entries)[i].info;
        uint32_t count = 0;
        const uint64_t count_at = r.file_pos();
        NAVE_RETURN_IF_ERROR(r.Get(&count));
        if (count > kMaxLevels || uint64_t(count) * entry_bytes > r.remaining()) {
            return DataLossError(
                "{} brick {} levels @0x{:x}: {} levels (at most {}, of {} bytes each in the {} "
                "bytes left)",
                name, i, count_at, count, kMaxLevels, entry_bytes, r.remaining());
        }
        b.levels.resize(count);
        for (uint32_t k = 1; k <= count; ++k) {
            LevelInfo& l = b.levels[k - 1];
            const uint64_t at = r.file_pos();
            const size_t start = r.pos();
            uint32_t flags = 0;
            NAVE_RETURN_IF_ERROR(r.Get(&l.error));
            NAVE_RETURN_IF_ERROR(r.Get(&flags));
            NAVE_RETURN_IF_ERROR(r.Get(&l.triangle_count));
            NAVE_RETURN_IF_ERROR(r.Get(&l.vertex_count));
            NAVE_RETURN_IF_ERROR(r.Get(&l.decoded_bytes));
            NAVE_RETURN_IF_ERROR(GetSection(r, &l.mesh));
            NAVE_RETURN_IF_ERROR(r.Skip(entry_bytes - (r.pos() - start)));
            l.has_normals = (flags & kBrickHasNormals) != 0;
            l.has_uvs = (flags & kBrickHasUvs) != 0;
            const float previous_error = k == 1 ? 0.f : b.levels[k - 2].error;
            if (!std::isfinite(l.error) || l.error < 0 || (k > 1 && !(l.error > previous_error))) {
                return DataLossError(
                    "{} brick {} level {} @0x{:x}: error {} (expected a finite error >= 0, "
                    "larger than level {}'s {})",
                    name, i, k, at, l.error, k - 1, previous_error);
            }
            const uint64_t finer_triangles =
                k == 1 ? b.triangle_count : b.levels[k - 2].triangle_count;
            if (l.triangle_count == 0 || l.triangle_count > finer_triangles) {
                return DataLossError(
                    "{} brick {} level {} @0x{:x}: {} triangles (expected 1 to level {}'s {})",
                    name, i, k, at, l.triangle_count, k - 1, finer_triangles);
            }
            const uint64_t expected =
                BrickMesh::BytesFor(l.vertex_count, l.triangle_count, l.has_normals, l.has_uvs);
            if (l.decoded_bytes != expected) {
                return DataLossError(
                    "{} brick {} level {} @0x{:x}: decoded size {} != {} implied by its {} "
                    "vertices and {} triangles",
                    name, i, k, at, l.decoded_bytes, expected, l.vertex_count, l.triangle_count);
            }
            if (l.mesh.length == 0 || !InPayloadArea(l.mesh, h))
                return OutsidePayloadArea(
                    l.mesh, h, fmt::format("{} brick {} level {} @0x{:x}: mesh ", name, i, k, at));
        }
    }
    if (r.remaining() != 0) {
        return DataLossError("{} levels @0x{:x}: {} bytes left after {} bricks", name, r.file_pos(),
                             r.remaining(), brick_count);
    }
    return Status::Ok();
}

// ---- occupancy

std::string EncodeOccupancy(const std::vector<RawBrickEntry>& entries) {
    ByteWriter w;
    w.Put(kOccupancyEntryBytes);
    w.Put(uint32_t(entries.size()));
    for (const RawBrickEntry& e : entries) PutSection(w, e.info.occupancy);
    return std::move(w.bytes());
}

Status DecodeOccupancy(std::string_view bytes, const RawHeader& h, const std::string& name,
                       std::vector<RawBrickEntry>* entries) {
    ByteReader r(bytes, name + " occupancy", h.occupancy.offset);
    NAVE_ASSIGN_OR_RETURN(const uint32_t entry_bytes,
                          ReadBrickTablePrefix(r, h, name, "occupancy", h.occupancy.offset,
                                               kOccupancyEntryBytes, entries->size()));
    const uint32_t brick_count = h.brick_count;
    NAVE_RETURN_IF_ERROR(CheckEntriesFill(r, name, "occupancy", brick_count, entry_bytes));
    for (uint32_t i = 0; i < brick_count; ++i) {
        SectionInfo& section = (*entries)[i].info.occupancy;
        const uint64_t at = r.file_pos();
        const size_t start = r.pos();
        NAVE_RETURN_IF_ERROR(GetSection(r, &section));
        NAVE_RETURN_IF_ERROR(r.Skip(entry_bytes - (r.pos() - start)));
        if (section.length > 0 && !InPayloadArea(section, h))
            return OutsidePayloadArea(section, h,
                                      fmt::format("{} brick {} occupancy @0x{:x}: ", name, i, at));
    }
    return Status::Ok();
}

// ---- medium

std::string EncodeMedium(const std::string& grid_name, const std::vector<RawBrickEntry>& entries) {
    ByteWriter w;
    w.Put(kMediumEntryBytes);
    w.Put(uint32_t(entries.size()));
    w.PutString(grid_name);
    for (const RawBrickEntry& e : entries) {
        const BrickMediumInfo& m = e.info.medium;
        const size_t start = w.size();
        PutSection(w, m.grid);
        w.Put(m.active_voxels);
        w.Put(m.max_density);
        w.Put(uint32_t(0));  // reserved
        w.Put(m.decoded_bytes);
        NAVE_CHECK_EQ(w.size() - start, size_t(kMediumEntryBytes));
    }
    return std::move(w.bytes());
}

Status DecodeMedium(std::string_view bytes, const RawHeader& h, const std::string& name,
                    std::vector<RawBrickEntry>* entries, std::string* grid_name) {
    ByteReader r(bytes, name + " medium", h.medium.offset);
    NAVE_ASSIGN_OR_RETURN(const uint32_t entry_bytes,
                          ReadBrickTablePrefix(r, h, name, "medium", h.medium.offset,
                                               kMediumEntryBytes, entries->size()));
    const uint32_t brick_count = h.brick_count;
    NAVE_RETURN_IF_ERROR(r.GetString(grid_name));
    if (grid_name->empty())
        return DataLossError("{} medium @0x{:x}: the table names no grid", name, h.medium.offset);
    NAVE_RETURN_IF_ERROR(CheckEntriesFill(r, name, "medium", brick_count, entry_bytes));
    for (uint32_t i = 0; i < brick_count; ++i) {
        BrickMediumInfo& m = (*entries)[i].info.medium;
        const uint64_t at = r.file_pos();
        const size_t start = r.pos();
        uint32_t reserved = 0;
        NAVE_RETURN_IF_ERROR(GetSection(r, &m.grid));
        NAVE_RETURN_IF_ERROR(r.Get(&m.active_voxels));
        NAVE_RETURN_IF_ERROR(r.Get(&m.max_density));
        NAVE_RETURN_IF_ERROR(r.Get(&reserved));
        NAVE_RETURN_IF_ERROR(r.Get(&m.decoded_bytes));
        NAVE_RETURN_IF_ERROR(r.Skip(entry_bytes - (r.pos() - start)));
        if (m.grid.length == 0) {
            if (m.active_voxels != 0 || m.max_density != 0 || m.decoded_bytes != 0) {
                return DataLossError(
                    "{} brick {} medium @0x{:x}: no section, yet {} voxels, majorant {} and {} "
                    "decoded bytes (expected 0 for each)",
                    name, i, at, m.active_voxels, m.max_density, m.decoded_bytes);
            }
            continue;
        }
        if (!InPayloadArea(m.grid, h))
            return OutsidePayloadArea(m.grid, h,
                                      fmt::format("{} brick {} medium @0x{:x}: ", name, i, at));
        if (m.active_voxels == 0 || !std::isfinite(m.max_density) || m.max_density < 0) {
            return DataLossError(
                "{} brick {} medium @0x{:x}: {} voxels, majorant {} (expected at least 1 voxel "
                "and a finite majorant >= 0)",
                name, i, at, m.active_voxels, m.max_density);
        }
    }
    return Status::Ok();
}

// ---- materials

std::string EncodeMaterials(const std::vector<MaterialRecord>& materials) {
    ByteWriter w;
    for (const MaterialRecord& m : materials) {
        ByteWriter rec;
        rec.PutString(m.name);
        for (float v : m.diffuse) rec.Put(v);
        for (float v : m.specular) rec.Put(v);
        for (float v : m.emission) rec.Put(v);
        rec.Put(m.ior);
        rec.Put(m.opacity);
        rec.Put(m.shininess);
        rec.Put(m.metallic);
        rec.Put(m.roughness);
        rec.Put(uint32_t(m.textures.size()));
        for (const auto& [slot, path] : m.textures) {
            rec.PutString(slot);
            rec.PutString(path);
        }
        rec.Put(m.alpha_cutoff);  // 1.1
        // Each record carries its length so that a newer minor version may append fields to it.
        w.Put(uint32_t(rec.size()));
        w.bytes().append(rec.bytes());
    }
    return std::move(w.bytes());
}

StatusOr<std::vector<MaterialRecord>> DecodeMaterials(std::string_view bytes, const RawHeader& h,
                                                      const std::string& name) {
    ByteReader table(bytes, name + " materials", h.materials.offset);
    // Each record takes at least its 4-byte length.
    if (h.material_count > bytes.size() / 4) {
        return DataLossError("{} materials @0x{:x}: {} materials cannot fit in {} bytes", name,
                             h.materials.offset, h.material_count, bytes.size());
    }
    std::vector<MaterialRecord> materials(h.material_count);
    for (uint32_t i = 0; i < h.material_count; ++i) {
        uint32_t record_bytes = 0;
        const uint64_t at = table.file_pos();
        NAVE_RETURN_IF_ERROR(table.Get(&record_bytes));
        if (record_bytes > table.remaining()) {
            return DataLossError(
                "{} material {} @0x{:x}: record of {} bytes overruns the table ({} bytes left)",
                name, i, at, record_bytes, table.remaining());
        }
        ByteReader r(bytes.substr(table.pos(), record_bytes),
                     fmt::format("{} material {}", name, i), table.file_pos());
        NAVE_RETURN_IF_ERROR(table.Skip(record_bytes));
        MaterialRecord& m = materials[i];
        NAVE_RETURN_IF_ERROR(r.GetString(&m.name));
        for (float& v : m.diffuse) NAVE_RETURN_IF_ERROR(r.Get(&v));
        for (float& v : m.specular) NAVE_RETURN_IF_ERROR(r.Get(&v));
        for (float& v : m.emission) NAVE_RETURN_IF_ERROR(r.Get(&v));
        NAVE_RETURN_IF_ERROR(r.Get(&m.ior));
        NAVE_RETURN_IF_ERROR(r.Get(&m.opacity));
        NAVE_RETURN_IF_ERROR(r.Get(&m.shininess));
        NAVE_RETURN_IF_ERROR(r.Get(&m.metallic));
        NAVE_RETURN_IF_ERROR(r.Get(&m.roughness));
        uint32_t texture_count = 0;
        NAVE_RETURN_IF_ERROR(r.Get(&texture_count));
        if (texture_count > r.remaining() / 8) {
            return DataLossError("{} material {} @0x{:x}: {} textures cannot fit in {} bytes", name,
                                 i, at, texture_count, r.remaining());
        }
        for (uint32_t t = 0; t < texture_count; ++t) {
            std::string slot, path;
            NAVE_RETURN_IF_ERROR(r.GetString(&slot));
            NAVE_RETURN_IF_ERROR(r.GetString(&path));
            m.textures[slot] = path;
        }
        // Fields appended by later minor versions: absent in older records, which keep the
        // defaults.
        if (r.remaining() >= sizeof(float)) NAVE_RETURN_IF_ERROR(r.Get(&m.alpha_cutoff));
    }
    if (table.remaining() != 0) {
        return DataLossError("{} materials @0x{:x}: {} bytes left after {} records", name,
                             table.file_pos(), table.remaining(), h.material_count);
    }
    return materials;
}

}  // namespace nave::store::format
