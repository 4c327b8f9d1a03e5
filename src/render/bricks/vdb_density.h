#pragma once
// A medium's density from a float grid of OpenVDB (through the plugin of src/volumes/vdb_plugin.h):
// constant over each voxel's cell, so its integral along a ray is an exact sum over the voxels the
// ray crosses (OpenVDB's DDA). Either a whole grid read from a `.vdb` file, or one brick's piece of
// a grid stored in the bricks (store::BrickMediumInfo), which counts only inside the brick's cell:
// a voxel that straddles two cells is in both pieces, and each adds the part of it on its side.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

#include "src/core/status.h"
#include "src/render/bricks/density_field.h"
#include "src/volumes/vdb_plugin.h"

namespace nave::render {

class VdbDensity final : public DensityField {
  public:
    /// The grid `grid_name` of `file` times `scale`. Errors: the plugin's
    /// (VdbPlugin::ReadScalarGrid).
    static StatusOr<std::shared_ptr<const VdbDensity>> Load(const std::filesystem::path& file,
                                                            const std::string& grid_name,
                                                            float scale);
    /// A brick's piece of a stored grid (the bytes of its medium section) times `scale`, counted
    /// only inside `cell`. `what` names the piece in errors (VdbPlugin::ReadScalarGridBytes).
    static StatusOr<std::shared_ptr<const VdbDensity>> FromPiece(std::span<const std::byte> bytes,
                                                                 const std::string& what,
                                                                 float scale, const Bounds3f& cell);

    Bounds3f bounds() const override { return bounds_; }
    float Walk(const Vec3f& o, const Vec3f& d, float t0, float t1, float target,
               float* integral) const override;
    float Density(const Vec3f& p) const override;
    float detail_m() const override { return grid_->voxel_size(); }
    /// Bytes the grid takes in memory.
    uint64_t memory_bytes() const { return grid_->memory_bytes(); }

  private:
    VdbDensity(std::unique_ptr<volumes::ScalarGrid> grid, float scale, const Bounds3f& clip);
    std::unique_ptr<volumes::ScalarGrid> grid_;
    float scale_;
    Bounds3f bounds_;  ///< the grid's bounds within the clip box
    bool empty_ = false;
};

}  // namespace nave::render
