#include "src/render/transport/photon_guide.h"

#include <algorithm>
#include <cmath>

#include "src/core/check.h"

namespace nave::render {

PhotonGuide::PhotonGuide(int cells, float half_extent)
    : cells_(cells),
      half_extent_(half_extent),
      cell_size_(2 * half_extent / float(cells)),
      learned_(size_t(cells) * cells, 0.0) {
    NAVE_CHECK(cells > 0 && cells <= 256);  // cell indices fit in uint16_t below kNoCell
}

uint16_t PhotonGuide::Cell(float x, float y) const {
    const int i = int(std::floor((x + half_extent_) / cell_size_));
    const int j = int(std::floor((y + half_extent_) / cell_size_));
    if (i < 0 || j < 0 || i >= cells_ || j >= cells_) return kNoCell;
    return uint16_t(j * cells_ + i);
}

Point2f PhotonGuide::Sample(float u_cell, Point2f u) const {
    NAVE_CHECK(trained());
    size_t c =
        size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end(), double(u_cell)) - (cdf_.begin() + 1));
    // Skip cells of zero probability that a u on a boundary of the CDF could land on.
    while (c + 1 < learned_.size() && learned_[c] <= 0) ++c;
    c = std::min(c, learned_.size() - 1);
    const int i = int(c) % cells_, j = int(c) / cells_;
    return Point2f(-half_extent_ + (float(i) + u.x) * cell_size_,
                   -half_extent_ + (float(j) + u.y) * cell_size_);
}

float PhotonGuide::Pdf(float x, float y) const {
    if (!trained()) return 0;
    const uint16_t c = Cell(x, y);
    if (c == kNoCell) return 0;
    return float(learned_[c] / total_) / (cell_size_ * cell_size_);
}

void PhotonGuide::Learn(std::span<const uint16_t> cells, std::span<const float> deposited) {
    NAVE_CHECK_EQ(cells.size(), deposited.size());
    for (size_t k = 0; k < cells.size(); ++k) Add(cells[k], deposited[k]);
    Update();
}

bool PhotonGuide::SetLearned(std::vector<double> learned) {
    if (learned.size() != learned_.size()) return false;
    learned_ = std::move(learned);
    Update();
    return true;
}

void PhotonGuide::Update() {
    total_ = 0;
    cdf_.assign(1, 0.0);
    for (double v : learned_) {
        total_ += v;
        cdf_.push_back(total_);
    }
    if (total_ > 0) {
        for (double& c : cdf_) c /= total_;
        cdf_.back() = 1.0;
    }
}

}  // namespace nave::render
