#pragma once
// Where photons from a distant light (the sun) are worth starting, learned from the photons already
// traced: importance-driven photon emission (after Peter & Pietrek 1998, "Importance driven
// construction of photon maps"), here as a grid over the plane facing the light whose cells are
// sampled in proportion to the light the photons started there brought to the visible points.
//
// Photons start on the plane facing the light at 2 R from the model's centre (R its bounding
// radius), at frame coordinates (x, y) in [-R, R]^2. After each photon pass, Learn adds each
// photon's deposited luminance to its start cell: the sum over a cell, divided by the photons
// traced, is a Monte Carlo estimate of the light the cell's lines bring to the image, whatever
// density the photons were drawn from (each photon's power already carries 1 / density). Sampling
// cells in proportion to it puts the photons where the image needs them: the windows and what
// reflects into them.

#include <cstdint>
#include <span>
#include <vector>

#include "src/core/sampling.h"
#include "src/core/vecmath.h"

namespace nave::render {

class PhotonGuide {
  public:
    /// A grid of cells x cells over [-half_extent, half_extent]^2 (metres).
    PhotonGuide(int cells, float half_extent);

    /// Whether anything has been learned yet (Sample and Pdf need it).
    bool trained() const { return total_ > 0; }
    /// The cell of plane point (x, y), or kNoCell outside the grid.
    uint16_t Cell(float x, float y) const;
    static constexpr uint16_t kNoCell = 0xffff;
    /// A plane point drawn in proportion to what was learned: a cell from `u_cell`, uniform inside
    /// it from `u`. Requires trained().
    Point2f Sample(float u_cell, Point2f u) const;
    /// The density (per m^2) with which Sample draws (x, y); 0 outside the grid or before training.
    float Pdf(float x, float y) const;
    /// Adds what photon k brought to the image, deposited[k] (luminance at the visible points), to
    /// its start cell cells[k] (kNoCell: not a photon of this light). The spans have one entry per
    /// photon of the pass, in photon order, so the result does not depend on the thread count.
    void Learn(std::span<const uint16_t> cells, std::span<const float> deposited);
    /// Learn one photon at a time: Add each, then Update once.
    void Add(uint16_t cell, float deposited) {
        if (cell != kNoCell && deposited > 0 && deposited < 1e30f) learned_[cell] += deposited;
    }
    void Update();
    /// What Learn has gathered so far (per cell), for a checkpoint; SetLearned restores it and
    /// updates the distribution, exactly as after the Learn that gathered it.
    const std::vector<double>& learned() const { return learned_; }
    /// False (and nothing changed) if `learned` does not hold one value per cell.
    bool SetLearned(std::vector<double> learned);

  private:
    int cells_;
    float half_extent_;
    float cell_size_;
    std::vector<double> learned_;  // per cell, the sum of deposited luminance
    std::vector<double> cdf_;      // normalised, cells^2 + 1 entries
    double total_ = 0;
};

}  // namespace nave::render
