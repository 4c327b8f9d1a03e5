#pragma once
// A medium's density from a float grid of an OpenVDB file (through the plugin of
// src/volumes/vdb_plugin.h): constant over each voxel's cell, so its integral along a ray is an
// exact sum over the voxels the ray crosses (OpenVDB's DDA).

#include <filesystem>
#include <memory>
#include <string>

#include "src/core/status.h"
#include "src/render/scene/media/density_field.h"
#include "src/volumes/vdb_plugin.h"

namespace nave::render {

class VdbDensity final : public DensityField {
  public:
    /// The grid `grid_name` of `file` times `scale`. Errors: the plugin's
    /// (VdbPlugin::ReadScalarGrid).
    static StatusOr<std::shared_ptr<const VdbDensity>> Load(const std::filesystem::path& file,
                                                            const std::string& grid_name,
                                                            float scale);

    Bounds3f bounds() const override { return grid_->bounds(); }
    float Integral(const Vec3f& o, const Vec3f& d, float t_max) const override;
    float Reach(const Vec3f& o, const Vec3f& d, float t_max, float target) const override;

  private:
    VdbDensity(std::unique_ptr<volumes::ScalarGrid> grid, float scale)
        : grid_(std::move(grid)), scale_(scale) {}
    std::unique_ptr<volumes::ScalarGrid> grid_;
    float scale_;
};

}  // namespace nave::render
