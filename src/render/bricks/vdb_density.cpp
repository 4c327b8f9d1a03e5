#include "src/render/bricks/vdb_density.h"

#include <algorithm>
#include <limits>

namespace nave::render {

VdbDensity::VdbDensity(std::unique_ptr<volumes::ScalarGrid> grid, float scale, const Bounds3f& clip)
    : grid_(std::move(grid)), scale_(scale) {
    const Bounds3f b = grid_->bounds();
    bounds_ = Bounds3f(Max(b.min, clip.min), Min(b.max, clip.max));
    // A piece that does not reach into its cell adds nothing anywhere.
    empty_ = !(bounds_.min.x <= bounds_.max.x && bounds_.min.y <= bounds_.max.y &&
               bounds_.min.z <= bounds_.max.z);
}

StatusOr<std::shared_ptr<const VdbDensity>> VdbDensity::Load(const std::filesystem::path& file,
                                                             const std::string& grid_name,
                                                             float scale) {
    NAVE_ASSIGN_OR_RETURN(const volumes::VdbPlugin* plugin, volumes::LoadVdbPlugin());
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<volumes::ScalarGrid> grid,
                          plugin->ReadScalarGrid(file, grid_name));
    const Bounds3f all = grid->bounds();
    return std::shared_ptr<const VdbDensity>(new VdbDensity(std::move(grid), scale, all));
}

StatusOr<std::shared_ptr<const VdbDensity>> VdbDensity::FromPiece(std::span<const std::byte> bytes,
                                                                  const std::string& what,
                                                                  float scale,
                                                                  const Bounds3f& cell) {
    NAVE_ASSIGN_OR_RETURN(const volumes::VdbPlugin* plugin, volumes::LoadVdbPlugin());
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<volumes::ScalarGrid> grid,
                          plugin->ReadScalarGridBytes(bytes, what));
    return std::shared_ptr<const VdbDensity>(new VdbDensity(std::move(grid), scale, cell));
}

float VdbDensity::Walk(const Vec3f& o, const Vec3f& d, float t0, float t1, float target,
                       float* integral) const {
    constexpr float kNever = std::numeric_limits<float>::infinity();
    *integral = 0;
    float a, b;
    if (empty_ || !(t1 > t0) || !(scale_ > 0) || !ClipRayToBounds(bounds_, o, d, t0, t1, &a, &b))
        return kNever;
    double sum = 0;
    const double goal = double(target) / double(scale_);
    float reached = kNever;
    grid_->March(o, d, a, b, [&](float v0, float v1, float value) {
        const double here = double(value) * double(v1 - v0);
        if (value > 0 && sum + here >= goal) {
            // Constant over the voxel: the integral grows linearly across it.
            reached = v0 + float((goal - sum) / double(value));
            sum = goal;
            return false;
        }
        sum += here;
        return true;
    });
    *integral = reached < kNever ? target : float(sum * scale_);
    return reached;
}

float VdbDensity::Density(const Vec3f& p) const {
    if (empty_ || !bounds_.Contains(p)) return 0;
    return scale_ * grid_->Value(p);
}

}  // namespace nave::render
