#pragma once
// The on-disk layout of a `.nave` store (internal to nave_store; docs/store-format.md is the
// reference). Everything is little-endian. This file owns the byte layout of the header and of the
// tables; the brick payloads (Draco + LZ4) are brick_codec's business.
//
//   [header, header_bytes]  [brick payloads ...]  [provenance] [directory] [tree] [materials]
//   [levels (3.1)] [medium (3.3)] [occupancy (3.4)]
//
// The tables are written after the payloads and the header last, so a file cut anywhere fails to
// open.

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "src/core/status.h"
#include "store/brick_tree.h"
#include "store/material_record.h"
#include "store/store_info.h"

namespace nave::store::format {

static_assert(std::endian::native == std::endian::little,
              "the store format is little-endian; add byte swaps");

/// The first 8 bytes of every store.
inline constexpr char kMagic[8] = {'N', 'A', 'V', 'E', 'S', 'T', 'O', 'R'};
/// Size of the version 1.0 header, the smallest; the header itself records its size so a newer
/// minor may grow it.
inline constexpr uint32_t kHeaderBytes = 256;
/// Size of the header this nave writes: 3.3 grew it by the medium table's section, 3.4 by the
/// occupancy table's (older readers take the size from the header and skip what they do not know).
inline constexpr uint32_t kCurrentHeaderBytes = 304;
/// The smallest header of a 3.3 store: the one that holds the medium table's section.
inline constexpr uint32_t kMediumHeaderBytes = 280;
/// The smallest header of a 3.4 store: the one that holds the occupancy table's section.
inline constexpr uint32_t kOccupancyHeaderBytes = 304;
/// Bytes every version has at the start of the header: magic, major, minor, header size.
inline constexpr uint32_t kHeaderPrefixBytes = 16;
/// Size of one directory entry and one tree node in version 1.0 (recorded in the header).
inline constexpr uint32_t kDirectoryEntryBytes = 128;
inline constexpr uint32_t kTreeNodeBytes = 20;

/// Bytes of the levels table's prefix (uint32 entry size, uint32 brick count) and of one level's
/// entry in version 3.1 (the prefix records it, so a newer minor may grow it).
inline constexpr uint32_t kLevelsPrefixBytes = 8;
inline constexpr uint32_t kLevelEntryBytes = 56;
/// Most levels a brick may have (more is a corrupt count).
inline constexpr uint32_t kMaxLevels = 16;

/// Bytes of the medium table's prefix (uint32 entry size, uint32 brick count; the grid's name
/// follows) and of one brick's entry in version 3.3 (the prefix records it, so a newer minor may
/// grow it).
inline constexpr uint32_t kMediumPrefixBytes = 8;
inline constexpr uint32_t kMediumEntryBytes = 48;

/// Bytes of the occupancy table's prefix (uint32 entry size, uint32 brick count) and of one
/// brick's entry in version 3.4 (its section: offset, length, checksum).
inline constexpr uint32_t kOccupancyPrefixBytes = 8;
inline constexpr uint32_t kOccupancyEntryBytes = 24;

/// Directory entry flags (also those of a level entry).
inline constexpr uint32_t kBrickHasNormals = 1u << 0;
inline constexpr uint32_t kBrickHasUvs = 1u << 1;

/// The header as stored, beyond what StoreHeader exposes.
struct RawHeader {
    uint16_t major = kFormatMajor;
    uint16_t minor = kFormatMinor;
    uint32_t header_bytes = kCurrentHeaderBytes;
    uint64_t file_bytes = 0;
    GlobalGrid grid;
    Bounds3f bounds;
    uint64_t triangle_count = 0;
    uint64_t source_triangle_count = 0;
    uint32_t brick_count = 0;
    uint32_t material_count = 0;
    uint32_t tree_node_count = 0;
    uint32_t directory_entry_bytes = kDirectoryEntryBytes;
    uint32_t tree_node_bytes = kTreeNodeBytes;
    SectionInfo provenance;
    SectionInfo directory;
    SectionInfo tree;
    SectionInfo materials;
    SectionInfo levels;  ///< 3.1; length 0 in stores without levels (and zero in older headers)
    SectionInfo medium;  ///< 3.3; length 0 in stores without a medium (and zero in older headers)
    SectionInfo occupancy;  ///< 3.4; length 0 in stores without occupancy grids
};

/// A directory entry as stored: BrickInfo plus flags.
struct RawBrickEntry {
    BrickInfo info;
    uint32_t flags = 0;
};

/// Appends little-endian values to a byte string.
class ByteWriter {
  public:
    template <typename T>
    void Put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const size_t at = bytes_.size();
        bytes_.resize(at + sizeof(T));
        std::memcpy(bytes_.data() + at, &v, sizeof(T));
    }
    void PutBounds(const Bounds3f& b);
    /// u32 length, then the bytes.
    void PutString(std::string_view s);
    void PutZeros(size_t n) { bytes_.append(n, '\0'); }
    size_t size() const { return bytes_.size(); }
    std::string& bytes() { return bytes_; }

  private:
    std::string bytes_;
};

/// Reads little-endian values from a table with bounds checks; errors name the table and the file
/// offset.
class ByteReader {
  public:
    /// `what` names the table in errors ("abbey.nave directory"); `file_offset` is where `bytes`
    /// start.
    ByteReader(std::string_view bytes, std::string what, uint64_t file_offset)
        : bytes_(bytes), what_(std::move(what)), file_offset_(file_offset) {}

    template <typename T>
    Status Get(T* v) {
        static_assert(std::is_trivially_copyable_v<T>);
        NAVE_RETURN_IF_ERROR(Need(sizeof(T)));
        std::memcpy(v, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return Status::Ok();
    }
    Status GetBounds(Bounds3f* b);
    Status GetString(std::string* s);
    Status Skip(size_t n);
    size_t pos() const { return pos_; }
    size_t remaining() const { return bytes_.size() - pos_; }
    /// File offset of the next byte (for messages).
    uint64_t file_pos() const { return file_offset_ + pos_; }
    const std::string& what() const { return what_; }

  private:
    Status Need(size_t n) const;
    std::string_view bytes_;
    std::string what_;
    uint64_t file_offset_ = 0;
    size_t pos_ = 0;
};

/// Serializes the header into exactly `h.header_bytes` bytes (at least what its version's fields
/// take), its checksum in the last 8.
std::string EncodeHeader(const RawHeader& h);
/// Parses and checks a header read from the start of the file: magic, version (refusing another
/// major, naming both), size, checksum. `name` is the file name for messages; `file_bytes` its
/// actual size.
StatusOr<RawHeader> DecodeHeader(std::string_view bytes, const std::string& name,
                                 uint64_t file_bytes);

std::string EncodeProvenance(const StoreProvenance& p);
StatusOr<StoreProvenance> DecodeProvenance(std::string_view bytes, const std::string& name,
                                           uint64_t offset);

std::string EncodeDirectory(const std::vector<RawBrickEntry>& entries);
StatusOr<std::vector<RawBrickEntry>> DecodeDirectory(std::string_view bytes, const RawHeader& h,
                                                     const std::string& name);

std::string EncodeTree(const BrickTree& tree);
StatusOr<BrickTree> DecodeTree(std::string_view bytes, const RawHeader& h, const std::string& name);

/// The levels table: every brick's levels (BrickInfo::levels), in brick order.
std::string EncodeLevels(const std::vector<RawBrickEntry>& entries);
/// Fills `entries[i].info.levels` from the table, checking counts, errors (finite, >= 0,
/// increasing), decoded sizes and that each level's mesh section lies in the payload area.
Status DecodeLevels(std::string_view bytes, const RawHeader& h, const std::string& name,
                    std::vector<RawBrickEntry>* entries);

/// The medium table: the grid's name and every brick's piece of it (BrickInfo::medium), in brick
/// order.
std::string EncodeMedium(const std::string& grid_name, const std::vector<RawBrickEntry>& entries);
/// The occupancy table: every brick's occupancy section (BrickInfo::occupancy), in brick order.
std::string EncodeOccupancy(const std::vector<RawBrickEntry>& entries);
/// Fills `entries[i].info.occupancy` from the table, checking the brick count, the entry size and
/// that every section lies in the payload area. DataLoss naming `name`, the brick and the offset.
Status DecodeOccupancy(std::string_view bytes, const RawHeader& h, const std::string& name,
                       std::vector<RawBrickEntry>* entries);
/// Fills `entries[i].info.medium` and `grid_name` from the table, checking the brick count, the
/// name, that a piece has voxels and a finite majorant >= 0, that a brick without a piece has no
/// counts, and that each piece's section lies in the payload area.
Status DecodeMedium(std::string_view bytes, const RawHeader& h, const std::string& name,
                    std::vector<RawBrickEntry>* entries, std::string* grid_name);

std::string EncodeMaterials(const std::vector<MaterialRecord>& materials);
StatusOr<std::vector<MaterialRecord>> DecodeMaterials(std::string_view bytes, const RawHeader& h,
                                                      const std::string& name);

}  // namespace nave::store::format
