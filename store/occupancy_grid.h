#pragma once
// Where a brick's full mesh has triangles, as a coarse grid of bits, so that a ray whose segment in
// the brick crosses only empty voxels goes on to the next brick without the brick being loaded
// (docs/pager.md, "Rays that cross a brick's air"). A camera ray down the abbey's nave crosses the
// cells of pillars and vaults it never touches; without this, each such crossing costs the
// brick's load under a budget. The answer is exact in the only direction that matters: a segment
// called empty meets no triangle of the brick, so skipping the brick gives the ray the same next
// stop a trace that missed would have.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/core/vecmath.h"

namespace nave::store {

class OccupancyGrid {
  public:
    /// Voxels along each axis of the brick's geometry box.
    static constexpr int kResolution = 64;
    /// What one grid takes in memory.
    static constexpr uint64_t kMemoryBytes =
        uint64_t(kResolution) * kResolution * kResolution / 8 + 64;

    /// The voxels of the box of `positions` that the boxes of the triangles `indices` (three per
    /// triangle) overlap, each box grown by a thousandth of a voxel so that a triangle on a
    /// voxel's face marks both sides. Cost: one pass over the triangles.
    static OccupancyGrid Of(std::span<const Vec3f> positions, std::span<const uint32_t> indices);

    /// The grid as a store's occupancy section holds it (format 3.4; docs/store-format.md,
    /// "Occupancy"): its box, then its bits, LZ4-compressed. Empty for a grid of no triangles.
    std::string Encode() const;
    /// A grid from Encode's bytes. DataLoss naming `what` (e.g. "abbey.nave brick 12 occupancy")
    /// for bytes that are not one: another resolution, a box that is not finite, bits that do not
    /// decompress to the grid's size.
    static StatusOr<OccupancyGrid> Decode(std::string_view bytes, const std::string& what);
    /// Whether no triangle marked it (Of over an empty mesh): every segment is empty.
    bool empty() const { return empty_box_; }

    /// Whether o + t d for t in [t0, t1] crosses no marked voxel: no triangle of the mesh lies on
    /// it. False where unsure (a degenerate direction, a box of no extent). Thread-safe.
    bool SegmentEmpty(const Vec3f& o, const Vec3f& d, float t0, float t1) const;

    /// The share of voxels marked (for statistics and tests).
    double MarkedFraction() const;

  private:
    bool Marked(int x, int y, int z) const {
        const uint32_t i = uint32_t((z * kResolution + y) * kResolution + x);
        return (bits_[i >> 6] >> (i & 63)) & 1u;
    }

    Vec3d origin_;      // the box's lower corner
    Vec3d voxel_size_;  // per axis
    bool empty_box_ = true;
    std::vector<uint64_t> bits_;
};

}  // namespace nave::store
