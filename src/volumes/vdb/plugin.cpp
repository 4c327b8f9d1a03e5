// nave's OpenVDB plugin (libnave_vdb.so): the implementation of volumes/vdb_plugin.h. Loaded on
// first use by LoadVdbPlugin; see that header for why OpenVDB is not linked into `nave` itself.

#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/io/Stream.h>
#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Count.h>
#include <openvdb/tools/RayIntersector.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <sstream>

#include "src/core/memory.h"
#include "src/volumes/vdb/file_layout.h"
#include "src/volumes/vdb_plugin.h"

namespace nave::volumes::vdb {
namespace {

using RayD = openvdb::math::Ray<double>;
/// Finds the spans of a ray that cross active leaves (8^3 voxels) or tiles: OpenVDB's hierarchical
/// DDA (Museth 2014, "Hierarchical digital differential analyzer for efficient ray-marching in
/// OpenVDB", SIGGRAPH Talks) over a boolean copy of the grid's topology.
using ActiveSpans = openvdb::tools::VolumeRayIntersector<openvdb::FloatGrid, /*NodeLevel=*/0, RayD>;

/// A float grid whose transform is a uniform scale and a translation (checked when read).
class VdbScalarGrid final : public ScalarGrid {
  public:
    explicit VdbScalarGrid(openvdb::FloatGrid::ConstPtr grid) : grid_(std::move(grid)) {
        voxel_m_ = grid_->voxelSize().x();
        // Without active voxels the box OpenVDB gives is inverted, of +-2^31 voxels: such a grid
        // has empty bounds and no spans to march.
        if (grid_->activeVoxelCount() == 0) return;
        const openvdb::CoordBBox box = grid_->evalActiveVoxelBoundingBox();
        // Voxel ijk's cell is [i - 1/2, i + 1/2] in index space: OpenVDB puts its centre at ijk.
        const openvdb::Vec3d lo = grid_->indexToWorld(box.min().asVec3d() - openvdb::Vec3d(0.5));
        const openvdb::Vec3d hi = grid_->indexToWorld(box.max().asVec3d() + openvdb::Vec3d(0.5));
        bounds_ = Bounds3f(Vec3f(float(std::min(lo.x(), hi.x())), float(std::min(lo.y(), hi.y())),
                                 float(std::min(lo.z(), hi.z()))),
                           Vec3f(float(std::max(lo.x(), hi.x())), float(std::max(lo.y(), hi.y())),
                                 float(std::max(lo.z(), hi.z()))));
        spans_ = std::make_unique<const ActiveSpans>(*grid_);
    }

    Bounds3f bounds() const override { return bounds_; }
    uint64_t memory_bytes() const override {
        return uint64_t(grid_->memUsage()) + (spans_ ? uint64_t(spans_->tree().memUsage()) : 0);
    }
    uint64_t active_voxels() const override { return uint64_t(grid_->activeVoxelCount()); }

    float voxel_size() const override { return float(voxel_m_); }

    float Value(const Vec3f& p) const override {
        // Outside the bounds every value is the background (0), and index coordinates there may
        // overflow a voxel coordinate.
        if (!spans_ || !bounds_.Contains(p)) return 0;
        // Voxel ijk's cell is [ijk - 1/2, ijk + 1/2] in index space.
        const openvdb::Vec3d x = grid_->worldToIndex(openvdb::Vec3d(p.x, p.y, p.z));
        const openvdb::Coord ijk(int32_t(std::floor(x.x() + 0.5)), int32_t(std::floor(x.y() + 0.5)),
                                 int32_t(std::floor(x.z() + 0.5)));
        return grid_->tree().getValue(ijk);
    }

    void March(const Vec3f& o, const Vec3f& d, float t_begin, float t_end,
               const std::function<bool(float, float, float)>& visit) const override {
        if (!(t_end > t_begin) || !spans_) return;
        // In index space, shifted by half a voxel so that the cell a point lies in is the floor
        // of its coordinates (the convention of OpenVDB's DDA and of the intersector's node
        // boxes). Index time is world time / voxel size.
        const openvdb::Vec3d eye =
            grid_->worldToIndex(openvdb::Vec3d(o.x, o.y, o.z)) + openvdb::Vec3d(0.5);
        const openvdb::Vec3d dir(d.x, d.y, d.z);
        // A shallow copy per call: its accessor is not thread-safe, the topology is shared.
        ActiveSpans spans(*spans_);
        if (!spans.setIndexRay(RayD(eye, dir, t_begin / voxel_m_, t_end / voxel_m_))) return;
        // Unregistered: the grid never changes, and a registered accessor would lock the tree's
        // table of accessors on every ray (TBB's concurrent_hash_map).
        auto accessor = grid_->getConstUnsafeAccessor();
        double s0 = 0, s1 = 0;
        // Only the spans across active leaves and tiles hold density: voxel by voxel there.
        while (spans.march(s0, s1)) {
            openvdb::math::DDA<RayD, 0> dda(RayD(eye, dir, s0, s1));
            do {
                const double t0 = dda.time(), t1 = dda.next();
                if (t1 > t0 && !visit(float(t0 * voxel_m_), float(t1 * voxel_m_),
                                      accessor.getValue(dda.voxel())))
                    return;
            } while (dda.step());
        }
    }

  private:
    openvdb::FloatGrid::ConstPtr grid_;
    std::unique_ptr<const ActiveSpans> spans_;
    Bounds3f bounds_;
    double voxel_m_ = 1;
};

/// An OpenVDB exception's message, cut to a line: on a damaged file OpenVDB may quote a "name" of
/// millions of bytes read from where a length was expected.
std::string Brief(const std::exception& e) {
    constexpr size_t kMaxChars = 200;
    std::string message = e.what();
    if (message.size() > kMaxChars) message = message.substr(0, kMaxChars) + "...";
    for (char& c : message)
        if (c == '\n' || c == '\r' || c == '\0') c = ' ';
    return message;
}

void InitializeOnce() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

/// `base` as a density grid: float values, a uniform scale and translation, non-negative finite
/// active values and background 0. Errors are InvalidArgument naming `where` and the grid `name`.
StatusOr<openvdb::FloatGrid::Ptr> CheckedDensityGrid(const openvdb::GridBase::Ptr& base,
                                                     const std::string& where,
                                                     const std::string& name) {
    openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid)
        return InvalidArgumentError("{}: grid '{}' holds {} values, not a float density", where,
                                    name, base->valueType());
    const openvdb::math::Transform& transform = grid->transform();
    const openvdb::Vec3d voxel = grid->voxelSize();
    const openvdb::math::MapBase& map = *transform.baseMap();
    const bool scale_and_translation = map.isType<openvdb::math::UniformScaleTranslateMap>() ||
                                       map.isType<openvdb::math::UniformScaleMap>() ||
                                       map.isType<openvdb::math::TranslationMap>() ||
                                       map.isType<openvdb::math::ScaleTranslateMap>() ||
                                       map.isType<openvdb::math::ScaleMap>();
    if (!transform.isLinear() || !grid->hasUniformVoxels() || !scale_and_translation)
        return InvalidArgumentError(
            "{}: grid '{}': its transform ({}) is not a uniform scale and translation", where, name,
            transform.baseMap()->type());
    if (!(voxel.x() > 0))
        return InvalidArgumentError("{}: grid '{}': voxel size {} is not positive", where, name,
                                    voxel.x());
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        if (!(*it >= 0) || !std::isfinite(*it))
            return InvalidArgumentError(
                "{}: grid '{}': density {} at voxel ({}, {}, {}) is "
                "not a finite, non-negative number",
                where, name, *it, it.getCoord().x(), it.getCoord().y(), it.getCoord().z());
    }
    if (grid->background() != 0.f)
        return InvalidArgumentError("{}: grid '{}': background {} is not 0", where, name,
                                    grid->background());
    return grid;
}

/// Index box of the voxels whose cells overlap the world box `box` (closed: a cell touching it
/// counts). Voxel ijk's cell is [ijk - 1/2, ijk + 1/2] in index space (OpenVDB puts its centre at
/// ijk), so it overlaps [lo, hi] when lo - 1/2 <= ijk <= hi + 1/2. The transform is a scale and a
/// translation (CheckedDensityGrid), which maps the box's corners to the index box's corners.
openvdb::CoordBBox VoxelsOverlapping(const openvdb::math::Transform& transform,
                                     const Bounds3f& box) {
    if (box.Empty()) return openvdb::CoordBBox();
    const openvdb::Vec3d a =
        transform.worldToIndex(openvdb::Vec3d(box.min.x, box.min.y, box.min.z));
    const openvdb::Vec3d b =
        transform.worldToIndex(openvdb::Vec3d(box.max.x, box.max.y, box.max.z));
    // Far beyond any grid's coordinates, yet safe to convert to int32.
    constexpr double kLimit = double(1 << 30);
    openvdb::Coord lo, hi;
    for (int axis = 0; axis < 3; ++axis) {
        const double from = std::clamp(std::min(a[axis], b[axis]) - 0.5, -kLimit, kLimit);
        const double to = std::clamp(std::max(a[axis], b[axis]) + 0.5, -kLimit, kLimit);
        lo[axis] = int32_t(std::ceil(from));
        hi[axis] = int32_t(std::floor(to));
    }
    return openvdb::CoordBBox(lo, hi);
}

/// A density grid without active voxels: a medium that would be nowhere, most likely not what the
/// file was meant to hold.
Status EmptyGridError(const std::string& where, const std::string& name) {
    return InvalidArgumentError("{}: grid '{}' has no active voxels: its density is 0 everywhere",
                                where, name);
}

/// The names of the grids in an open file, comma-separated ("none" for a file without grids).
std::string GridNames(openvdb::io::File& in) {
    std::string names;
    for (auto it = in.beginName(); it != in.endName(); ++it)
        names += (names.empty() ? "" : ", ") + it.gridName();
    return names.empty() ? "none" : names;
}

/// Bytes a float leaf (8^3 voxels) takes in memory with its values loaded.
uint64_t LoadedLeafBytes() {
    static const uint64_t bytes =
        openvdb::FloatTree::LeafNodeType(openvdb::Coord(0), 0.f).memUsage();
    return bytes;
}

/// What the cut will hold at once for a box of `voxels` active voxels (CutScalarGrid's
/// memory_limit): the topology (kept) and the region's own; the leaves holding the voxels, once
/// as read, once in the piece, once serialized. `voxels_per_leaf`: the grid's mean over its
/// leaves, since a leaf is read whole however few of its voxels are active (a tile's voxels fill
/// leaves of the piece: counted alike, which over-estimates them).
uint64_t EstimatedCutBytes(uint64_t topology_bytes, uint64_t voxels, double voxels_per_leaf) {
    const double leaves = double(voxels) / std::max(1.0, voxels_per_leaf);
    return 2 * topology_bytes + uint64_t(3.0 * std::ceil(leaves) * double(LoadedLeafBytes()));
}

/// VdbPlugin::CutScalarGrid, letting OpenVDB's exceptions through (the caller turns them into a
/// Status). Memory: the grid's topology (value masks, no values: delayed loading), kept to count
/// its voxels and each box's, then, box by box, the box's region as read (the topology again and
/// the values of the leaves that overlap the box: File::readGrid(name, bbox) reads no other
/// leaf's values) and the piece.
StatusOr<GridCutSummary> CutGrid(const std::filesystem::path& file, const std::string& name,
                                 std::span<const Bounds3f> boxes, uint64_t memory_limit,
                                 const std::function<Status(size_t, GridPiece)>& emit) {
    const std::string where = file.string();
    NAVE_RETURN_IF_ERROR(CheckFileLayout(file));
    openvdb::io::File in(where);
    // OpenVDB would first copy a file of up to 500 MB to a temporary one, in case it changed
    // while leaves wait to be loaded; every leaf this reads is loaded before the file closes.
    in.setCopyMaxBytes(0);
    in.open(/*delayLoad=*/true);
    if (!in.hasGrid(name)) {
        const std::string names = GridNames(in);
        in.close();
        return InvalidArgumentError("{}: no grid '{}' (grids there: {})", where, name, names);
    }
    // The value type and the transform, before any voxel is read.
    NAVE_ASSIGN_OR_RETURN(openvdb::FloatGrid::Ptr header,
                          CheckedDensityGrid(in.readGridMetadata(name), where, name));
    const openvdb::math::Transform::Ptr transform = header->transform().copy();

    GridCutSummary summary;
    // With delayed loading the leaves' values stay in the file: counting reads the masks.
    const openvdb::FloatGrid::Ptr topology =
        openvdb::gridPtrCast<openvdb::FloatGrid>(in.readGrid(name));
    if (!topology) return InvalidArgumentError("{}: grid '{}' is not a float grid", where, name);
    summary.active_voxels = topology->activeVoxelCount();
    if (summary.active_voxels == 0) return EmptyGridError(where, name);
    const openvdb::CoordBBox active = topology->evalActiveVoxelBoundingBox();
    summary.topology_bytes = openvdb::tools::memUsage(topology->tree());
    summary.peak_bytes = summary.topology_bytes;
    const double voxels_per_leaf =
        double(topology->tree().activeLeafVoxelCount()) /
        double(std::max<openvdb::Index64>(1, topology->tree().leafCount()));
    if (memory_limit > 0 && 2 * summary.topology_bytes > memory_limit) {
        return ResourceExhaustedError(
            "{}: grid '{}': its topology alone ({} voxels in {} leaves) needs {} while it is cut, "
            "more than the {} allowed: give more --memory",
            where, name, summary.active_voxels, topology->tree().leafCount(),
            FormatBytes(2 * summary.topology_bytes), FormatBytes(memory_limit));
    }
    const openvdb::Vec3d lo = transform->indexToWorld(active.min().asVec3d() - openvdb::Vec3d(0.5));
    const openvdb::Vec3d hi = transform->indexToWorld(active.max().asVec3d() + openvdb::Vec3d(0.5));
    for (const openvdb::Vec3d& corner : {lo, hi})
        summary.bounds.Extend(Vec3f(float(corner.x()), float(corner.y()), float(corner.z())));

    // A voxel whose cell overlaps several boxes goes into each; it counts as kept in the first.
    // Only boxes within a voxel of each other can share one: those whose index boxes overlap.
    std::vector<openvdb::CoordBBox> wanted(boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) wanted[i] = VoxelsOverlapping(*transform, boxes[i]);
    uint64_t kept = 0;
    const double voxel = transform->voxelSize().x();
    std::vector<const openvdb::CoordBBox*> earlier;
    for (size_t i = 0; i < boxes.size(); ++i) {
        const openvdb::CoordBBox& want = wanted[i];
        if (want.empty() || !want.hasOverlap(active)) continue;
        const uint64_t box_voxels = openvdb::tools::countActiveVoxels(topology->tree(), want);
        if (box_voxels == 0) continue;
        const uint64_t estimate =
            EstimatedCutBytes(summary.topology_bytes, box_voxels, voxels_per_leaf);
        if (memory_limit > 0 && estimate > memory_limit) {
            return ResourceExhaustedError(
                "{}: grid '{}': the piece for box {} of {} ({} voxels) needs about {} while it is "
                "cut, more than the {} allowed: give more --memory, or smaller bricks",
                where, name, i, boxes.size(), box_voxels, FormatBytes(estimate),
                FormatBytes(memory_limit));
        }
        earlier.clear();
        for (size_t j = 0; j < i; ++j)
            if (wanted[j].hasOverlap(want)) earlier.push_back(&wanted[j]);
        // A voxel more on each side than the cells that overlap the box: readGrid rounds the
        // world box to voxels its own way.
        const openvdb::BBoxd read_box(
            openvdb::Vec3d(boxes[i].min.x, boxes[i].min.y, boxes[i].min.z) - openvdb::Vec3d(voxel),
            openvdb::Vec3d(boxes[i].max.x, boxes[i].max.y, boxes[i].max.z) + openvdb::Vec3d(voxel));
        NAVE_ASSIGN_OR_RETURN(openvdb::FloatGrid::Ptr region,
                              CheckedDensityGrid(in.readGrid(name, read_box), where, name));
        openvdb::FloatGrid::Ptr piece = openvdb::FloatGrid::create(0.f);
        piece->setName(name);
        piece->setTransform(transform->copy());
        piece->setGridClass(region->getGridClass());
        GridPiece out;
        for (auto it = region->cbeginValueOn(); it; ++it) {
            // A leaf's voxel, or an active tile's box of voxels.
            openvdb::CoordBBox voxels;
            it.getBoundingBox(voxels);
            voxels.intersect(want);
            if (voxels.empty()) continue;
            piece->tree().fill(voxels, *it, /*active=*/true);
            out.max_value = std::max(out.max_value, *it);
            for (auto ijk = voxels.begin(); ijk; ++ijk) {
                const bool seen = std::any_of(earlier.begin(), earlier.end(),
                                              [&](const auto* box) { return box->isInside(*ijk); });
                kept += seen ? 0 : 1;
            }
        }
        out.active_voxels = piece->activeVoxelCount();
        if (out.active_voxels == 0) continue;
        out.memory_bytes = VdbScalarGrid(piece).memory_bytes();
        std::ostringstream bytes(std::ios::binary);
        openvdb::io::Stream(bytes).write(openvdb::GridCPtrVec{piece});
        const std::string serialized = std::move(bytes).str();
        summary.peak_bytes =
            std::max<uint64_t>(summary.peak_bytes, summary.topology_bytes + region->memUsage() +
                                                       out.memory_bytes + 2 * serialized.size());
        out.bytes.resize(serialized.size());
        std::memcpy(out.bytes.data(), serialized.data(), serialized.size());
        NAVE_RETURN_IF_ERROR(emit(i, std::move(out)));
    }
    in.close();
    summary.voxels_outside = summary.active_voxels - std::min(kept, summary.active_voxels);
    return summary;
}

class Plugin final : public VdbPlugin {
  public:
    StatusOr<std::unique_ptr<ScalarGrid>> ReadScalarGrid(const std::filesystem::path& file,
                                                         const std::string& name) const override {
        InitializeOnce();
        std::error_code ec;
        if (!std::filesystem::exists(file, ec))
            return NotFoundError("{}: no such file", file.string());
        openvdb::GridBase::Ptr base;
        try {
            NAVE_RETURN_IF_ERROR(CheckFileLayout(file));
            openvdb::io::File in(file.string());
            in.open(/*delayLoad=*/false);
            if (!in.hasGrid(name)) {
                const std::string names = GridNames(in);
                in.close();
                return InvalidArgumentError("{}: no grid '{}' (grids there: {})", file.string(),
                                            name, names);
            }
            base = in.readGrid(name);
            in.close();
        } catch (const std::exception& e) {
            // OpenVDB reports a file that is not its format, or cut short, by exceptions.
            return InvalidArgumentError("{}: not a readable OpenVDB file: {}", file.string(),
                                        Brief(e));
        }
        NAVE_ASSIGN_OR_RETURN(openvdb::FloatGrid::Ptr grid,
                              CheckedDensityGrid(base, file.string(), name));
        if (grid->activeVoxelCount() == 0) return EmptyGridError(file.string(), name);
        return std::unique_ptr<ScalarGrid>(std::make_unique<VdbScalarGrid>(grid));
    }

    StatusOr<std::unique_ptr<ScalarGrid>> ReadScalarGridBytes(
        std::span<const std::byte> bytes, const std::string& what) const override {
        InitializeOnce();
        openvdb::GridPtrVecPtr grids;
        try {
            NAVE_RETURN_IF_ERROR(CheckStreamLayout(bytes, what));
            std::istringstream in(
                std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                std::ios::binary);
            // OpenVDB does not check every read: past the end of cut-short bytes it would take
            // what follows for a length and allocate gigabytes. A short read throws instead.
            in.exceptions(std::ios::failbit | std::ios::badbit);
            // Not delayed: a delayed Stream copies the bytes to a temporary file and reads each
            // leaf on first touch, where a damaged one would throw outside this block.
            grids = openvdb::io::Stream(in, /*delayLoad=*/false).getGrids();
        } catch (const std::exception& e) {
            return DataLossError("{}: not a readable OpenVDB grid: {}", what, Brief(e));
        }
        if (!grids || grids->size() != 1)
            return DataLossError("{}: {} grids where one was stored", what,
                                 grids ? grids->size() : 0);
        const openvdb::GridBase::Ptr& base = grids->front();
        auto checked = CheckedDensityGrid(base, what, base->getName());
        if (!checked.ok()) return Status(StatusCode::kDataLoss, checked.status().message());
        return std::unique_ptr<ScalarGrid>(std::make_unique<VdbScalarGrid>(*checked));
    }

    StatusOr<GridCutSummary> CutScalarGrid(
        const std::filesystem::path& file, const std::string& name, std::span<const Bounds3f> boxes,
        uint64_t memory_limit,
        const std::function<Status(size_t, GridPiece)>& emit) const override {
        InitializeOnce();
        std::error_code ec;
        if (!std::filesystem::exists(file, ec))
            return NotFoundError("{}: no such file", file.string());
        try {
            return CutGrid(file, name, boxes, memory_limit, emit);
        } catch (const std::exception& e) {
            // OpenVDB reports a file that is not its format, or cut short, by exceptions.
            return InvalidArgumentError("{}: not a readable OpenVDB file: {}", file.string(),
                                        Brief(e));
        }
    }

    Status WriteScalarGrid(const std::filesystem::path& file, const std::string& name,
                           const Vec3f& origin, float voxel_m, const Vec3i& dims,
                           const std::function<float(int, int, int)>& value) const override {
        InitializeOnce();
        openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.f);
        grid->setName(name);
        grid->setGridClass(openvdb::GRID_FOG_VOLUME);
        // Voxel ijk's centre at origin + (ijk + 1/2) voxel_m: its cell starts at origin + ijk.
        openvdb::math::Transform::Ptr transform =
            openvdb::math::Transform::createLinearTransform(voxel_m);
        transform->postTranslate(openvdb::Vec3d(origin.x + 0.5 * voxel_m, origin.y + 0.5 * voxel_m,
                                                origin.z + 0.5 * voxel_m));
        grid->setTransform(transform);
        // Unregistered: nothing else touches the grid while it is filled.
        auto accessor = grid->getUnsafeAccessor();
        for (int k = 0; k < dims.z; ++k)
            for (int j = 0; j < dims.y; ++j)
                for (int i = 0; i < dims.x; ++i)
                    if (const float v = value(i, j, k); v != 0.f)
                        accessor.setValue(openvdb::Coord(i, j, k), v);
        try {
            openvdb::GridPtrVec grids{grid};
            openvdb::io::File out(file.string());
            out.write(grids);
            out.close();
        } catch (const std::exception& e) {
            return IoError("{}: cannot write the grid '{}': {}", file.string(), name, Brief(e));
        }
        return Status::Ok();
    }
};

}  // namespace
}  // namespace nave::volumes::vdb

extern "C" __attribute__((visibility("default"))) nave::volumes::VdbPlugin* NaveCreateVdbPlugin(
    int version) {
    if (version != nave::volumes::kVdbPluginVersion) return nullptr;
    return new nave::volumes::vdb::Plugin();
}
