#pragma once
// What a render did, for the final summary and the EXR metadata (render_summary.h): the streams'
// counts and the integrator's own.

#include <cstdint>

#include "src/render/stream/stream_stats.h"

namespace nave::render {

struct RenderStats : StreamStats {
    double wall_seconds = 0;
    uint64_t camera_paths = 0;
    uint64_t photons = 0;  ///< photons emitted
    uint64_t peak_rss_bytes = 0;
    /// The render's own estimate of its image's relative mean squared error (luminance), from its
    /// two halves of samples (docs/render.md, "Noise"); NaN with fewer than two passes or
    /// iterations.
    double noise_relmse = 0;
    int samples_per_pixel = 0;  ///< path mode: passes completed
    int iterations = 0;         ///< photon mode: SPPM iterations completed
    /// Path mode with render.path_guiding: the guide's cells with histograms, and those guiding.
    uint32_t guide_cells = 0;
    uint32_t guide_cells_guiding = 0;
    /// With render.LearnsSkyWindows: the regions that chose their windows (SkyWindows::regions).
    uint64_t sky_window_regions = 0;
};

}  // namespace nave::render
