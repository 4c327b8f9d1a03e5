#pragma once
// `nave generate dust`: a drifting-dust density grid for showing a heterogeneous medium: puffs of
// dust of smooth edges, denser near the floor, written as an OpenVDB float grid "density" through
// the plugin (vdb_plugin.h).

#include <cstdint>
#include <filesystem>

#include "src/core/status.h"
#include "src/core/vecmath.h"

namespace nave::volumes {

/// What WriteDriftingDust makes.
struct DustOptions {
    Bounds3f box{{0, -13, 0}, {56, 13, 20}};  ///< metres; default: the abbey's nave and aisles
    float voxel_m = 0.25f;                    ///< voxel side
    int puffs = 40;                           ///< how many puffs
    uint64_t seed = 1;
};

/// Writes the dust of `options` to `file`: at each voxel's centre a sum of Gaussian puffs
/// (radii 1.5 to 5 m, heights weighted toward the floor), clamped to 1; values under 1e-3 left
/// empty. Errors: the plugin's.
Status WriteDriftingDust(const std::filesystem::path& file, const DustOptions& options);

}  // namespace nave::volumes
