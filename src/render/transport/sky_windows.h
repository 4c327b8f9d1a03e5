#pragma once
// The sky's windows as lights chosen where they are seen. Inside the abbey the sky lights a point
// through a few of several hundred windows; next-event estimation that picks a window by its area
// sends most samples to windows the point cannot see. Here the portal triangles are grouped into
// windows (the cells of a grid of about 2 m in the abbey, so a lancet is a few windows), and for
// each region of the model (a grid cell and the side its surfaces face, as the path guide keys
// them) the light each window brought there is learned from the sky's photons at their first
// diffuse hit: what the photon carries is the sky's radiance in that direction through that pane,
// past whatever occludes it on the way, onto a surface facing that way, so the sums estimate a
// window's contribution (solid angle x radiance x transmittance x cosine x visibility) without
// modelling any of them. Next-event estimation then picks a window in proportion to it (Vévoda et
// al. 2018, "Bayesian online regression for adaptive direct illumination sampling", learns such
// per-region light selection from the estimator's own samples), mixed with the area-proportional
// and uniform strategies so that light the photons have not found yet keeps a nonzero density
// (LightSampler::SampleSky). The estimator's own samples teach it too: each of the sky's shadow
// rays that reaches the sky estimates the light of the window it crossed (radiance x
// transmittance x cosine / the pdf of its direction, unbiased whichever strategy drew it). Both
// sums are proportional to a window's light within a region, so their sum is too; the camera's
// shadow rays are many more than the sky's photons at first hits (150 k against some 3 k per
// iteration of the abbey at 480 x 320) and teach the regions the camera sees from the first
// iteration.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "src/core/byte_stream.h"
#include "src/core/sampling.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"

namespace nave::render {

class SkyPortals;

class SkyWindows {
  public:
    /// The windows of `portals` (which must outlive this) over the model's `bounds`, regions and
    /// windows both cells of about the longest axis / kCellsLongAxis. `photon_power`: the
    /// luminance of a typical photon, and `estimate_power` that of a shadow ray's estimate of a
    /// typical window's light: they set the fixed-point resolution of each kind of record.
    SkyWindows(const SkyPortals& portals, const Bounds3f& bounds, double photon_power,
               double estimate_power = 1.0);
    ~SkyWindows();
    SkyWindows(const SkyWindows&) = delete;
    SkyWindows& operator=(const SkyWindows&) = delete;

    static constexpr int kCellsLongAxis = 64;
    /// A region learns its windows once this many records (photons or shadow rays) reached it.
    static constexpr uint32_t kMinPhotons = 16;
    /// At most this many (region, window) sums are kept: beyond it, Update forgets those of the
    /// fewest photons (the least certain) down to three quarters of it.
    static constexpr size_t kMaxPairs = size_t(1) << 17;
    /// The bytes the windows hold at most: the sums and choices of kMaxPairs pairs, and the
    /// records of an iteration before Update, a few hundred thousand pairs (the render's memory
    /// reserve).
    static constexpr uint64_t kMemoryReserveBytes = kMaxPairs * 64 + (uint64_t(16) << 20);

    /// A region's learned choice of windows: entries [first, first + count) of the tables.
    struct Region {
        uint32_t first = 0, count = 0;
    };

    size_t window_count() const { return window_area_.size(); }
    /// Records a sky photon of luminance `power` that came straight through portal triangle
    /// `triangle` onto a surface of side `side` (PathGuide::SideOf) at `p`. Thread-safe; the sums
    /// are integers, so the order of records does not change them (nor the image with threads or
    /// the memory budget).
    void Record(const Vec3f& p, int side, uint32_t triangle, double power) {
        RecordFixed(p, side, triangle, power * photon_to_fixed_);
    }
    /// Records a shadow ray's estimate `estimate` of the light that portal triangle `triangle`'s
    /// window brings at `p`, on a surface of side `side`. Thread-safe, as Record.
    void RecordEstimate(const Vec3f& p, int side, uint32_t triangle, double estimate) {
        RecordFixed(p, side, triangle, estimate * estimate_to_fixed_);
    }
    /// Makes what was recorded so far the regions' choices. Not concurrent with anything else.
    void Update();
    /// In a distributed render, before Update: every process's records since the last Update,
    /// put together in every process by `gather` (RankGroup::GatherEverywhere), so that all learn
    /// the same choices from all the records (integer sums: the same as one process's). Not
    /// concurrent with anything else. Errors: gather's, and bytes that are not whole records.
    Status ShareRecords(
        const std::function<StatusOr<std::vector<std::byte>>(std::span<const std::byte>)>& gather);
    /// The learned choice at `p` on a surface of side `side`, or null where none was learned.
    const Region* Find(const Vec3f& p, int side) const;
    /// A point on a window that `region` chose with `u_window`, on one of its triangles chosen by
    /// area (from what is left of `u_window`), uniform on it from `u`.
    Vec3f SamplePoint(const Region& region, float u_window, Point2f u) const;
    /// The density per unit area with which SamplePoint picks a point on portal triangle
    /// `triangle`: the window's probability in `region` over the window's area.
    float AreaDensity(const Region& region, uint32_t triangle) const;

    /// Regions with a learned choice, and (window, region) pairs with light recorded.
    size_t regions() const { return regions_.size(); }
    size_t pairs() const { return sums_.size(); }
    /// Bytes of the learned sums and choices, for the memory summary.
    uint64_t MemoryBytes() const;

    /// Appends the recorded sums to `out`, for a checkpoint (the choices are remade from them).
    void SaveState(ByteWriter* out) const;
    /// Replaces the sums with what SaveState wrote and remakes the choices. Errors: DataLoss for
    /// truncated bytes or a window that does not exist.
    Status LoadState(ByteReader* in);

  private:
    struct Sum {
        uint64_t fixed = 0;  // luminance, fixed point
        uint32_t photons = 0;
    };
    struct ThreadSums;
    void RecordFixed(const Vec3f& p, int side, uint32_t triangle, double fixed);
    /// The sums in key order: region, then window.
    std::vector<std::pair<uint64_t, Sum>> SortedSums() const;
    /// Forgets the `count` sums of the fewest photons (ties by key: the same on every run).
    void Forget(size_t count);
    /// The region key of `p` and `side`, or kNoRegion outside the bounds.
    uint32_t RegionKey(const Vec3f& p, int side) const;
    static constexpr uint32_t kNoRegion = 0xffffffffu;

    const SkyPortals& portals_;
    Bounds3f bounds_;
    int res_[3] = {1, 1, 1};
    Vec3f inv_cell_;
    double photon_to_fixed_, estimate_to_fixed_;
    // Windows: each portal triangle's window; per window its triangles (by area CDF) and area.
    std::vector<uint32_t> triangle_window_;
    std::vector<uint32_t> window_first_;  // window w's triangles: window_triangles_[first[w],
                                          // first[w + 1])
    std::vector<uint32_t> window_triangles_;
    std::vector<float> window_triangle_cdf_;  // within each window, normalised
    std::vector<float> window_area_;
    // Learned: sums per (region << 32 | window), and per region its windows (sorted) with their
    // probabilities and CDF.
    std::unordered_map<uint64_t, Sum> sums_;
    std::unique_ptr<ThreadSums> pending_;
    std::unordered_map<uint32_t, Region> regions_;
    std::vector<uint32_t> choice_window_;
    std::vector<float> choice_probability_, choice_cdf_;
};

}  // namespace nave::render
