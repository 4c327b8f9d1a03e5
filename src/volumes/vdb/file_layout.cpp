// Checks of a `.vdb` file's or stream's layout before OpenVDB reads it (file_layout.h). The layout
// read here is OpenVDB's (io/Archive.cc, io/GridDescriptor.cc, MetaMap::readMeta): a header; the
// file's metadata; a grid count; per grid a descriptor (unique name, type name, instance parent
// name from file version 216, three 64-bit offsets) and, at the first offset, the grid's
// compression flags (from version 222), its metadata, its transform (a type name first), its
// topology and its values. Strings are a 32-bit length and that many bytes; metadata is a 32-bit
// count of entries, each a name, a type name, a 32-bit value size and the value.

#include "src/volumes/vdb/file_layout.h"

#include <openvdb/Metadata.h>
#include <openvdb/io/Archive.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/openvdb.h>

#include <cstdint>
#include <fstream>
#include <sstream>

namespace nave::volumes::vdb {
namespace {

/// Walks the layout of a stream of `size` bytes, checking every length against the bytes left
/// before anything is allocated for it. Every read is whole: the stream throws on a short one.
/// An Archive for its header reader, which also tags the stream with the file's version, as
/// OpenVDB's readers that follow need.
class LayoutReader final : public openvdb::io::Archive {
  public:
    LayoutReader(std::istream& in, uint64_t size, std::string where, StatusCode code)
        : in_(in), size_(size), where_(std::move(where)), code_(code) {}

    void ReadHeader() {
        readHeader(in_);
        setFormatVersion(in_);
        setLibraryVersion(in_);
        setDataCompression(in_);
    }
    int32_t ReadGridCount() { return readGridCount(in_); }
    static void SkipGridCompression(std::istream& in) { readGridCompression(in); }

    /// Skips a string, checking its length; `field` names it in the error.
    Status SkipString(const std::string& field) {
        const uint32_t length = ReadU32();
        NAVE_RETURN_IF_ERROR(CheckLength(length, field));
        in_.seekg(length, std::ios::cur);
        return Status::Ok();
    }

    /// Skips a MetaMap (`of` names it), checking every length in it, and that a value of a type
    /// OpenVDB knows to be of fixed size has that size: OpenVDB reads such a value by its type and
    /// the size given, when wrong, would put this walk and OpenVDB's reads out of step.
    Status SkipMetadata(const std::string& of) {
        const uint32_t count = ReadU32();
        // Each entry takes at least 12 bytes: the lengths of its name, type and value.
        if (uint64_t(count) * 12 > Left())
            return Error("{} lists {} entries at byte {}, more than the {} bytes left can hold", of,
                         count, Position() - 4, Left());
        for (uint32_t i = 0; i < count; ++i) {
            const std::string entry = fmt::format("{} entry {}", of, i);
            NAVE_RETURN_IF_ERROR(SkipString(entry + "'s name"));
            const uint32_t type_length = ReadU32();
            NAVE_RETURN_IF_ERROR(CheckLength(type_length, entry));
            std::string type(type_length, '\0');
            if (type_length > 0) in_.read(type.data(), type_length);
            const uint32_t value_bytes = ReadU32();
            const std::string value = fmt::format("{} ({})", entry, type);
            NAVE_RETURN_IF_ERROR(CheckLength(value_bytes, value));
            if (openvdb::Metadata::isRegisteredType(type)) {
                const uint32_t fixed = openvdb::Metadata::createMetadata(type)->size();
                // Variable-size types (strings) report 0 before they hold a value.
                if (fixed > 0 && fixed != value_bytes)
                    return Error("{} holds {} bytes at byte {}, where its type has {}", value,
                                 value_bytes, Position() - 4, fixed);
            }
            in_.seekg(value_bytes, std::ios::cur);
        }
        return Status::Ok();
    }

    /// Checks the names of the grid descriptor at the current position, and leaves it there for
    /// OpenVDB's GridDescriptor::read.
    Status CheckDescriptorNames(int32_t grid) {
        const std::streampos start = in_.tellg();
        const std::string of = "grid descriptor " + std::to_string(grid) + "'s ";
        NAVE_RETURN_IF_ERROR(SkipString(of + "name"));
        NAVE_RETURN_IF_ERROR(SkipString(of + "type"));
        if (fileVersion() >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
            NAVE_RETURN_IF_ERROR(SkipString(of + "instance parent"));
        in_.seekg(start);
        return Status::Ok();
    }

    /// Checks the head of grid `name` at the current position: compression flags, metadata and
    /// the transform's type name, all within `end` (the grid's end in a file).
    Status CheckGridHead(const std::string& name, uint64_t end) {
        const uint64_t whole = size_;
        size_ = end;
        SkipGridCompression(in_);
        Status status = SkipMetadata("grid '" + name + "' metadata");
        if (status.ok()) status = SkipString("grid '" + name + "' transform's type");
        size_ = whole;
        return status;
    }

  private:
    template <typename... Args>
    Status Error(fmt::format_string<Args...> format, Args&&... args) const {
        return Status(code_,
                      where_ + ": damaged: " + fmt::format(format, std::forward<Args>(args)...));
    }

    uint64_t Position() const { return uint64_t(in_.tellg()); }
    uint64_t Left() const { return size_ > Position() ? size_ - Position() : 0; }
    uint32_t ReadU32() {
        uint32_t value = 0;
        in_.read(reinterpret_cast<char*>(&value), sizeof value);
        return value;
    }
    Status CheckLength(uint32_t length, const std::string& field) const {
        if (length <= Left()) return Status::Ok();
        return Error("{} is {} bytes long at byte {}, past the end ({} bytes left)", field, length,
                     Position() - 4, Left());
    }

    std::istream& in_;
    uint64_t size_;
    std::string where_;
    StatusCode code_;
};

Status CheckFileGrids(const std::filesystem::path& file) {
    const std::string where = file.string();
    const uint64_t size = std::filesystem::file_size(file);
    std::ifstream in(where, std::ios::binary);
    in.exceptions(std::ios::failbit | std::ios::badbit | std::ios::eofbit);
    LayoutReader layout(in, size, where, StatusCode::kInvalidArgument);
    layout.ReadHeader();
    NAVE_RETURN_IF_ERROR(layout.SkipMetadata("the file's metadata"));
    const int32_t count = layout.ReadGridCount();
    if (count < 0) return InvalidArgumentError("{}: {} grids: not an OpenVDB file", where, count);
    for (int32_t i = 0; i < count; ++i) {
        NAVE_RETURN_IF_ERROR(layout.CheckDescriptorNames(i));
        openvdb::io::GridDescriptor grid;
        grid.read(in);
        const int64_t end = grid.getEndPos();
        if (!(grid.getGridPos() >= 0 && grid.getGridPos() <= grid.getBlockPos() &&
              grid.getBlockPos() <= end && uint64_t(end) <= size))
            return InvalidArgumentError(
                "{}: cut short or damaged: grid '{}' lies at bytes {}..{} of a file of {}", where,
                grid.gridName(), grid.getGridPos(), end, size);
        in.seekg(grid.getGridPos(), std::ios::beg);
        NAVE_RETURN_IF_ERROR(layout.CheckGridHead(grid.gridName(), uint64_t(end)));
        in.seekg(end, std::ios::beg);
    }
    return Status::Ok();
}

Status CheckStreamGrid(std::span<const std::byte> bytes, const std::string& what) {
    std::istringstream in(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                          std::ios::binary);
    in.exceptions(std::ios::failbit | std::ios::badbit | std::ios::eofbit);
    LayoutReader layout(in, bytes.size(), what, StatusCode::kDataLoss);
    layout.ReadHeader();
    NAVE_RETURN_IF_ERROR(layout.SkipMetadata("the stream's metadata"));
    // Checked before OpenVDB's Stream reserves room for every descriptor the count announces.
    if (const int32_t count = layout.ReadGridCount(); count != 1)
        return DataLossError("{}: {} grids where one was stored", what, count);
    NAVE_RETURN_IF_ERROR(layout.CheckDescriptorNames(0));
    openvdb::io::GridDescriptor grid;
    grid.read(in);
    // A stream is written without offsets: the grid follows its descriptor.
    return layout.CheckGridHead(grid.gridName(), bytes.size());
}

}  // namespace

Status CheckFileLayout(const std::filesystem::path& file) {
    try {
        return CheckFileGrids(file);
    } catch (const std::ios_base::failure&) {
        return InvalidArgumentError("{}: cut short: its {} bytes end inside a header or a length",
                                    file.string(), std::filesystem::file_size(file));
    }
}

Status CheckStreamLayout(std::span<const std::byte> bytes, const std::string& what) {
    try {
        return CheckStreamGrid(bytes, what);
    } catch (const std::ios_base::failure&) {
        return DataLossError("{}: cut short: its {} bytes end inside a header or a length", what,
                             bytes.size());
    }
}

}  // namespace nave::volumes::vdb
