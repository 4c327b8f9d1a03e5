#pragma once
// The interface of nave's OpenVDB plugin (libnave_vdb.so, built from src/volumes/vdb/): scalar
// grids read from and written to `.vdb` files, for the density of participating media. OpenVDB
// pulls in Boost, Blosc and log4cplus; linked into `nave`, every command would load them, so it
// lives in a plugin loaded on first use, as OpenImageIO does (src/imaging/oiio_plugin.h).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"

namespace nave::volumes {

/// Bumped whenever VdbPlugin's methods or the types they take change.
inline constexpr int kVdbPluginVersion = 4;

/// A grid of voxels, each of constant value over its cell, in world space. Immutable: thread-safe.
class ScalarGrid {
  public:
    virtual ~ScalarGrid() = default;
    /// The world box of the active voxels' cells; outside it every value is the background, 0.
    virtual Bounds3f bounds() const = 0;
    /// Bytes the grid takes in memory (OpenVDB's memUsage), for memory budgets.
    virtual uint64_t memory_bytes() const = 0;
    /// Active voxels (those of active tiles included): GridPiece::active_voxels of a piece read.
    virtual uint64_t active_voxels() const = 0;
    /// The side of a voxel, world units.
    virtual float voxel_size() const = 0;
    /// The value of the voxel whose cell holds world point `p` (0 outside the active voxels).
    virtual float Value(const Vec3f& p) const = 0;
    /// Calls `visit(t0, t1, value)` for the voxels the ray o + t d (d unit) crosses with t in
    /// [t_begin, t_end] (world units), front to back, until it returns false: every voxel of the
    /// active leaves and tiles it crosses; voxels elsewhere are 0 and skipped.
    virtual void March(const Vec3f& o, const Vec3f& d, float t_begin, float t_end,
                       const std::function<bool(float, float, float)>& visit) const = 0;
};

/// One piece of a grid cut along a box (VdbPlugin::CutScalarGrid).
struct GridPiece {
    /// OpenVDB's own serialization (io::Stream) of a float grid named as the source grid, with
    /// its transform, holding the source's active voxels whose cells overlap the box.
    std::vector<std::byte> bytes;
    uint64_t active_voxels = 0;
    float max_value = 0;        ///< largest active value: the piece's majorant
    uint64_t memory_bytes = 0;  ///< ScalarGrid::memory_bytes() of the piece once read
};

/// What CutScalarGrid saw of the whole grid.
struct GridCutSummary {
    uint64_t active_voxels = 0;  ///< in the source grid
    /// Active voxels whose cells overlap none of the boxes (outside them all: not in any piece).
    uint64_t voxels_outside = 0;
    Bounds3f bounds;  ///< world box of the source's active voxels' cells
    /// Bytes of the grid's topology (its tree without values, as delayed loading reads it).
    uint64_t topology_bytes = 0;
    /// The most the cut held at once, measured: the topology, one box's region as read (its
    /// topology and the values of the leaves overlapping the box), the piece and its bytes.
    uint64_t peak_bytes = 0;
};

/// The OpenVDB side. Every method is thread-safe; every failure is a Status naming the file.
class VdbPlugin {
  public:
    virtual ~VdbPlugin() = default;
    /// The float grid `grid` of `file`. A file that is not OpenVDB (or is cut short) is
    /// InvalidArgument naming it; a missing grid lists the grids there; a grid of another value
    /// type, a transform that is not a uniform scale and translation, a negative active value, or
    /// no active voxel at all is InvalidArgument naming the grid. A file whose offsets or lengths
    /// reach past its end is refused before OpenVDB allocates anything for them.
    virtual StatusOr<std::unique_ptr<ScalarGrid>> ReadScalarGrid(const std::filesystem::path& file,
                                                                 const std::string& grid) const = 0;
    /// A grid serialized as GridPiece::bytes; `what` names it in errors (e.g. "abbey.nave brick
    /// 12 medium"). Bytes that do not decode, or hold no float grid, are DataLoss naming `what`.
    virtual StatusOr<std::unique_ptr<ScalarGrid>> ReadScalarGridBytes(
        std::span<const std::byte> bytes, const std::string& what) const = 0;
    /// Cuts the float grid `grid` of `file` along `boxes` (world space), calling `emit(i, piece)`
    /// for every box i that some active voxel's cell overlaps, in order of i, and stopping at the
    /// first error `emit` returns. The file is read box by box, only the leaves that overlap it
    /// (OpenVDB's File::readGrid(name, bbox)), so the whole grid is never in memory at once. The
    /// grid is checked as ReadScalarGrid checks it (same errors), its values where a box reads
    /// them: voxels outside every box are counted, not read. With no boxes, it checks the file and
    /// the grid's type and transform and counts its voxels (reading their masks, not their values).
    /// `memory_limit` (bytes; 0: none) bounds what the cut holds at once: before a box's values
    /// are read, that is estimated from the topology (twice the topology, and three times the
    /// loaded leaves of the box's voxels: as read, in the piece, serialized), and a box over the
    /// limit is ResourceExhausted naming the file, the grid, the box and both sizes; with no
    /// boxes, the topology alone (twice) is checked.
    virtual StatusOr<GridCutSummary> CutScalarGrid(
        const std::filesystem::path& file, const std::string& grid, std::span<const Bounds3f> boxes,
        uint64_t memory_limit,
        const std::function<Status(size_t box, GridPiece piece)>& emit) const = 0;
    /// Writes a float grid named `grid` of `dims` voxels of side `voxel_m`, voxel (0, 0, 0)'s
    /// cell starting at `origin`, with value(i, j, k) (0 is left inactive), to `file`. IoError on
    /// failure.
    virtual Status WriteScalarGrid(const std::filesystem::path& file, const std::string& grid,
                                   const Vec3f& origin, float voxel_m, const Vec3i& dims,
                                   const std::function<float(int, int, int)>& value) const = 0;
};

/// The plugin, loaded once on first call: NAVE_VDB_PLUGIN if set, else libnave_vdb.so beside the
/// executable, else at the build tree's path, else through the library search path. Thread-safe.
StatusOr<const VdbPlugin*> LoadVdbPlugin();

}  // namespace nave::volumes

/// The plugin's one exported symbol: a new VdbPlugin if `version` is kVdbPluginVersion, else null.
extern "C" nave::volumes::VdbPlugin* NaveCreateVdbPlugin(int version);
