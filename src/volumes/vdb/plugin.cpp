// nave's OpenVDB plugin (libnave_vdb.so): the implementation of volumes/vdb_plugin.h. Loaded on
// first use by LoadVdbPlugin; see that header for why OpenVDB is not linked into `nave` itself.

#include <openvdb/io/File.h>
#include <openvdb/math/DDA.h>
#include <openvdb/math/Ray.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <mutex>

#include "src/volumes/vdb_plugin.h"

namespace nave::volumes::vdb {
namespace {

using RayD = openvdb::math::Ray<double>;

/// A float grid whose transform is a uniform scale and a translation (checked when read).
class VdbScalarGrid final : public ScalarGrid {
  public:
    explicit VdbScalarGrid(openvdb::FloatGrid::ConstPtr grid) : grid_(std::move(grid)) {
        const openvdb::CoordBBox box = grid_->evalActiveVoxelBoundingBox();
        // Voxel ijk's cell is [i - 1/2, i + 1/2] in index space: OpenVDB puts its centre at ijk.
        const openvdb::Vec3d lo = grid_->indexToWorld(box.min().asVec3d() - openvdb::Vec3d(0.5));
        const openvdb::Vec3d hi = grid_->indexToWorld(box.max().asVec3d() + openvdb::Vec3d(0.5));
        bounds_ = Bounds3f(Vec3f(float(std::min(lo.x(), hi.x())), float(std::min(lo.y(), hi.y())),
                                 float(std::min(lo.z(), hi.z()))),
                           Vec3f(float(std::max(lo.x(), hi.x())), float(std::max(lo.y(), hi.y())),
                                 float(std::max(lo.z(), hi.z()))));
        voxel_m_ = grid_->voxelSize().x();
    }

    Bounds3f bounds() const override { return bounds_; }

    void March(const Vec3f& o, const Vec3f& d, float t_begin, float t_end,
               const std::function<bool(float, float, float)>& visit) const override {
        if (!(t_end > t_begin)) return;
        // In index space, shifted by half a voxel so that the cell a point lies in is the floor
        // of its coordinates (the DDA's convention). Index time is world time / voxel size.
        const openvdb::Vec3d eye =
            grid_->worldToIndex(openvdb::Vec3d(o.x, o.y, o.z)) + openvdb::Vec3d(0.5);
        const RayD ray(eye, openvdb::Vec3d(d.x, d.y, d.z), t_begin / voxel_m_, t_end / voxel_m_);
        openvdb::math::DDA<RayD, 0> dda(ray);
        auto accessor = grid_->getConstAccessor();
        do {
            const double t0 = dda.time(), t1 = dda.next();
            if (t1 > t0 &&
                !visit(float(t0 * voxel_m_), float(t1 * voxel_m_), accessor.getValue(dda.voxel())))
                return;
        } while (dda.step());
    }

  private:
    openvdb::FloatGrid::ConstPtr grid_;
    Bounds3f bounds_;
    double voxel_m_ = 1;
};

void InitializeOnce() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
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
        std::string names;
        try {
            openvdb::io::File in(file.string());
            in.open(/*delayLoad=*/false);
            for (auto it = in.beginName(); it != in.endName(); ++it)
                names += (names.empty() ? "" : ", ") + it.gridName();
            if (!in.hasGrid(name)) {
                in.close();
                return InvalidArgumentError("{}: no grid '{}' (grids there: {})", file.string(),
                                            name, names.empty() ? "none" : names);
            }
            base = in.readGrid(name);
            in.close();
        } catch (const std::exception& e) {
            // OpenVDB reports a file that is not its format, or cut short, by exceptions.
            return InvalidArgumentError("{}: not a readable OpenVDB file: {}", file.string(),
                                        e.what());
        }
        openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!grid)
            return InvalidArgumentError("{}: grid '{}' holds {} values, not a float density",
                                        file.string(), name, base->valueType());
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
                "{}: grid '{}': its transform ({}) is not a uniform scale and translation",
                file.string(), name, transform.baseMap()->type());
        if (!(voxel.x() > 0))
            return InvalidArgumentError("{}: grid '{}': voxel size {} is not positive",
                                        file.string(), name, voxel.x());
        for (auto it = grid->cbeginValueOn(); it; ++it) {
            if (!(*it >= 0) || !std::isfinite(*it))
                return InvalidArgumentError(
                    "{}: grid '{}': density {} at voxel ({}, {}, {}) is "
                    "not a finite, non-negative number",
                    file.string(), name, *it, it.getCoord().x(), it.getCoord().y(),
                    it.getCoord().z());
        }
        if (grid->background() != 0.f)
            return InvalidArgumentError("{}: grid '{}': background {} is not 0", file.string(),
                                        name, grid->background());
        return std::unique_ptr<ScalarGrid>(std::make_unique<VdbScalarGrid>(grid));
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
        auto accessor = grid->getAccessor();
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
            return IoError("{}: cannot write the grid '{}': {}", file.string(), name, e.what());
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
