#include "src/volumes/dust.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "src/volumes/vdb_plugin.h"

namespace nave::volumes {
namespace {

struct Puff {
    Vec3f centre;
    float radius_m;
    float peak;
};

std::vector<Puff> Puffs(const DustOptions& options) {
    // std::mt19937_64's sequence is fixed by the standard: the same grid on every machine.
    std::mt19937_64 rng(options.seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    const Vec3f size = options.box.Diagonal();
    std::vector<Puff> puffs;
    for (int i = 0; i < options.puffs; ++i) {
        Puff p;
        const float h = u(rng);
        p.centre = options.box.min + Vec3f(u(rng) * size.x, u(rng) * size.y, h * h * size.z);
        p.radius_m = 1.f + 2.f * u(rng);
        p.peak = 0.3f + 0.7f * u(rng);
        puffs.push_back(p);
    }
    return puffs;
}

/// A puff is a Gaussian of standard deviation radius_m cut off at kReach of them (lowered by its
/// value there so that it reaches 0 continuously): clear air between the puffs, which rays cross
/// without walking voxels (the grid's empty leaves are skipped).
constexpr float kReach = 2.f;

float DensityOf(const std::vector<Puff>& puffs, const Vec3f& p) {
    const float edge = std::exp(-0.5f * kReach * kReach);
    float d = 0;
    for (const Puff& puff : puffs) {
        const Vec3f v = p - puff.centre;
        const float g = std::exp(-Dot(v, v) / (2 * puff.radius_m * puff.radius_m));
        if (g > edge) d += puff.peak * (g - edge) / (1 - edge);
    }
    return std::min(d, 1.f);
}

}  // namespace

Status WriteDriftingDust(const std::filesystem::path& file, const DustOptions& options) {
    if (!(options.voxel_m > 0) || options.box.Empty())
        return InvalidArgumentError("dust: the voxel size must be positive and the box not empty");
    NAVE_ASSIGN_OR_RETURN(const VdbPlugin* plugin, LoadVdbPlugin());
    const std::vector<Puff> puffs = Puffs(options);
    const Vec3f size = options.box.Diagonal();
    const Vec3i dims(int(std::ceil(size.x / options.voxel_m)),
                     int(std::ceil(size.y / options.voxel_m)),
                     int(std::ceil(size.z / options.voxel_m)));
    return plugin->WriteScalarGrid(
        file, "density", options.box.min, options.voxel_m, dims, [&](int i, int j, int k) {
            const Vec3f centre =
                options.box.min + Vec3f(i + 0.5f, j + 0.5f, k + 0.5f) * options.voxel_m;
            const float d = DensityOf(puffs, centre);
            return d < 1e-3f ? 0.f : d;
        });
}

}  // namespace nave::volumes
