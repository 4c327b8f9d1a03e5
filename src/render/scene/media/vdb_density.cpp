#include "src/render/scene/media/vdb_density.h"

#include <limits>

namespace nave::render {

StatusOr<std::shared_ptr<const VdbDensity>> VdbDensity::Load(const std::filesystem::path& file,
                                                             const std::string& grid_name,
                                                             float scale) {
    NAVE_ASSIGN_OR_RETURN(const volumes::VdbPlugin* plugin, volumes::LoadVdbPlugin());
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<volumes::ScalarGrid> grid,
                          plugin->ReadScalarGrid(file, grid_name));
    return std::shared_ptr<const VdbDensity>(new VdbDensity(std::move(grid), scale));
}

float VdbDensity::Integral(const Vec3f& o, const Vec3f& d, float t_max) const {
    float t0, t1;
    if (!ClipRayToBounds(grid_->bounds(), o, d, 0, t_max, &t0, &t1)) return 0.f;
    double sum = 0;
    grid_->March(o, d, t0, t1, [&](float a, float b, float value) {
        sum += double(value) * double(b - a);
        return true;
    });
    return float(sum * scale_);
}

float VdbDensity::Reach(const Vec3f& o, const Vec3f& d, float t_max, float target) const {
    float t0, t1;
    float reached = std::numeric_limits<float>::infinity();
    if (!ClipRayToBounds(grid_->bounds(), o, d, 0, t_max, &t0, &t1)) return reached;
    double sum = 0;
    const double goal = double(target) / double(scale_);
    grid_->March(o, d, t0, t1, [&](float a, float b, float value) {
        const double here = double(value) * double(b - a);
        if (value > 0 && sum + here >= goal) {
            // Constant over the voxel: the integral grows linearly across it.
            reached = a + float((goal - sum) / double(value));
            return false;
        }
        sum += here;
        return true;
    });
    return reached;
}

}  // namespace nave::render
