#pragma once
// Several inputs as one model: their triangles one after the other, their material tables joined
// with names made unique ("stone" from a.obj and "stone" from b.obj become "stone" and "stone.1").

#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

class MergedSource final : public TriangleSource {
  public:
    explicit MergedSource(std::vector<std::unique_ptr<TriangleSource>> sources);

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override;
    const std::vector<store::MaterialRecord>& materials() const override { return materials_; }
    std::string name() const override;
    std::string units() const override;
    /// The inputs' contents that say something, joined by '|'.
    std::string content() const override;
    uint64_t progress_done() const override;
    uint64_t progress_total() const override;
    /// The inputs' unit when they share one, else "units" (their sum is only a rough guide).
    std::string progress_unit() const override;
    uint64_t memory_bytes() const override;
    const ImportWarnings& warnings() const override { return warnings_; }

  private:
    uint32_t GlobalMaterial(size_t source, uint32_t local);
    void AddRemainingMaterials(size_t source);

    std::vector<std::unique_ptr<TriangleSource>> sources_;
    size_t current_ = 0;
    std::vector<std::vector<int64_t>> remap_;  // per source: local material -> global (-1 not yet)
    std::vector<store::MaterialRecord> materials_;
    std::unordered_set<std::string> names_;
    ImportWarnings warnings_;
    std::vector<uint64_t> finished_progress_;
};

}  // namespace nave::preprocess
