#include "store_reseal.h"

#include <cstring>

#include "src/core/check.h"
#include "src/core/hash.h"
#include "store/store_format.h"

namespace nave::fuzz {
namespace {

using store::format::kHeaderBytes;

// Where the fields this needs sit in a header and in a directory entry, learnt from the encoders
// with marker values rather than copied from docs/store-format.md, so a layout change cannot leave
// the target resealing the wrong bytes.
struct Layout {
    size_t file_bytes = 0;
    size_t table_checksum[4] =
        {};  // provenance, directory, tree, materials; offset and length precede
    size_t brick_count = 0;
    size_t entry_bytes = 0;
    size_t section_checksum[2] = {};   // mesh, side (within an entry); offset and length precede
    size_t levels_checksum = 0;        // the levels table's (3.1), in the header
    size_t level_checksum = 0;         // a level's mesh section's, within its levels-table entry
    size_t medium_table_checksum = 0;  // the medium table's (3.3), in the header
    size_t medium_checksum = 0;        // a piece's section's, within its medium-table entry
};

size_t Find(const std::string& bytes, uint64_t marker, size_t size) {
    const size_t at = bytes.find(std::string(reinterpret_cast<const char*>(&marker), size));
    NAVE_CHECK(at != std::string::npos) << "marker " << marker << " not found";
    return at;
}

Layout Learn() {
    Layout l;
    store::format::RawHeader h;
    h.file_bytes = 0x0123456789abcdefull;
    store::SectionInfo* tables[4] = {&h.provenance, &h.directory, &h.tree, &h.materials};
    for (int t = 0; t < 4; ++t) tables[t]->checksum = 0x5eed000000000001ull + uint64_t(t);
    h.brick_count = 0x7a11b0c5u;
    h.directory_entry_bytes = 0x6e7b1e5u;
    const std::string header = store::format::EncodeHeader(h);
    l.file_bytes = Find(header, h.file_bytes, 8);
    for (int t = 0; t < 4; ++t) l.table_checksum[t] = Find(header, tables[t]->checksum, 8);
    l.brick_count = Find(header, h.brick_count, 4);
    h.levels.checksum = 0x5eed0000000000ffull;
    l.levels_checksum = Find(store::format::EncodeHeader(h), h.levels.checksum, 8);
    l.entry_bytes = Find(header, h.directory_entry_bytes, 4);
    store::format::RawBrickEntry e;
    e.info.mesh.checksum = 0xc0de000000000001ull;
    e.info.side.checksum = 0xc0de000000000002ull;
    const std::string entry = store::format::EncodeDirectory({e});
    l.section_checksum[0] = Find(entry, e.info.mesh.checksum, 8);
    l.section_checksum[1] = Find(entry, e.info.side.checksum, 8);
    store::format::RawBrickEntry with_level;
    with_level.info.levels.emplace_back().mesh.checksum = 0xc0de000000000003ull;
    const std::string levels = store::format::EncodeLevels({with_level});
    // The table's prefix, then the brick's level count, then its entry.
    l.level_checksum = Find(levels, with_level.info.levels[0].mesh.checksum, 8) -
                       store::format::kLevelsPrefixBytes - 4;
    h.medium.checksum = 0x5eed00000000fffeull;
    l.medium_table_checksum = Find(store::format::EncodeHeader(h), h.medium.checksum, 8);
    store::format::RawBrickEntry with_medium;
    with_medium.info.medium.grid.checksum = 0xc0de000000000004ull;
    const std::string medium = store::format::EncodeMedium("g", {with_medium});
    // The table's prefix and the grid's name (a u32 length, then "g"), then the brick's entry.
    l.medium_checksum = Find(medium, with_medium.info.medium.grid.checksum, 8) -
                        store::format::kMediumPrefixBytes - 4 - 1;
    return l;
}

template <typename T>
T Load(const std::string& b, size_t at) {
    T v{};
    if (at + sizeof(T) <= b.size()) std::memcpy(&v, b.data() + at, sizeof(T));
    return v;
}

template <typename T>
void Store(std::string& b, size_t at, T v) {
    if (at + sizeof(T) <= b.size()) std::memcpy(b.data() + at, &v, sizeof(T));
}

// Writes the checksum of [offset, offset + length) at `at`, when that range lies inside the bytes.
void Seal(std::string& b, size_t at) {
    const uint64_t offset = Load<uint64_t>(b, at - 16), length = Load<uint64_t>(b, at - 8);
    if (offset > b.size() || length > b.size() - offset) return;
    Store(b, at, Checksum64(b.data() + offset, length));
}

}  // namespace

void ResealStore(std::string& bytes) {
    static const Layout l = Learn();
    if (bytes.size() < kHeaderBytes ||
        std::memcmp(bytes.data(), store::format::kMagic, sizeof(store::format::kMagic)) != 0)
        return;
    const uint32_t header_bytes = Load<uint32_t>(bytes, 12);
    if (header_bytes < kHeaderBytes || header_bytes > bytes.size()) return;
    Store(bytes, l.file_bytes, uint64_t(bytes.size()));
    // Brick sections first: their checksums live in the directory, whose own checksum follows.
    const size_t directory_at = l.table_checksum[1];
    const uint64_t dir_offset = Load<uint64_t>(bytes, directory_at - 16);
    const uint64_t dir_length = Load<uint64_t>(bytes, directory_at - 8);
    const uint32_t entry_bytes = Load<uint32_t>(bytes, l.entry_bytes);
    const uint32_t brick_count = Load<uint32_t>(bytes, l.brick_count);
    if (entry_bytes >= l.section_checksum[1] + 8 && dir_offset <= bytes.size() &&
        dir_length <= bytes.size() - dir_offset) {
        for (uint64_t i = 0; i < brick_count && (i + 1) * entry_bytes <= dir_length; ++i) {
            const size_t entry = size_t(dir_offset + i * entry_bytes);
            for (size_t s : l.section_checksum) Seal(bytes, entry + s);
        }
    }
    // Level sections: their checksums live in the levels table, sealed next.
    const uint64_t levels_offset = Load<uint64_t>(bytes, l.levels_checksum - 16);
    const uint64_t levels_length = Load<uint64_t>(bytes, l.levels_checksum - 8);
    if (levels_length >= store::format::kLevelsPrefixBytes && levels_offset <= bytes.size() &&
        levels_length <= bytes.size() - levels_offset) {
        const uint32_t level_bytes = Load<uint32_t>(bytes, levels_offset);
        const uint64_t end = levels_offset + levels_length;
        uint64_t at = levels_offset + store::format::kLevelsPrefixBytes;
        while (level_bytes >= l.level_checksum + 8 && at + 4 <= end) {
            const uint32_t count = Load<uint32_t>(bytes, at);
            at += 4;
            for (uint32_t k = 0; k < count && at + level_bytes <= end; ++k, at += level_bytes)
                Seal(bytes, at + l.level_checksum);
            if (count > 0 && at + level_bytes > end) break;
        }
    }
    // Pieces of the medium: their checksums live in the medium table, sealed next.
    const uint64_t medium_offset = Load<uint64_t>(bytes, l.medium_table_checksum - 16);
    const uint64_t medium_length = Load<uint64_t>(bytes, l.medium_table_checksum - 8);
    if (header_bytes >= l.medium_table_checksum + 8 &&
        medium_length >= store::format::kMediumPrefixBytes + 4 && medium_offset <= bytes.size() &&
        medium_length <= bytes.size() - medium_offset) {
        const uint32_t entry_bytes = Load<uint32_t>(bytes, medium_offset);
        const uint32_t count = Load<uint32_t>(bytes, medium_offset + 4);
        const uint32_t name_bytes =
            Load<uint32_t>(bytes, medium_offset + store::format::kMediumPrefixBytes);
        const uint64_t end = medium_offset + medium_length;
        uint64_t at = medium_offset + store::format::kMediumPrefixBytes + 4 + uint64_t(name_bytes);
        for (uint32_t i = 0;
             i < count && entry_bytes >= l.medium_checksum + 8 && at + entry_bytes <= end;
             ++i, at += entry_bytes)
            Seal(bytes, at + l.medium_checksum);
    }
    for (size_t t : l.table_checksum) Seal(bytes, t);
    Seal(bytes, l.levels_checksum);
    if (header_bytes >= l.medium_table_checksum + 8) Seal(bytes, l.medium_table_checksum);
    Store(bytes, header_bytes - 8, Checksum64(bytes.data(), header_bytes - 8));
}

}  // namespace nave::fuzz
