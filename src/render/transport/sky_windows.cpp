#include "src/render/transport/sky_windows.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>

#include "src/core/sampling.h"
#include "src/render/transport/light_sampling.h"
#include "src/render/transport/path_guide.h"

namespace nave::render {

struct SkyWindows::ThreadSums {
    tbb::enumerable_thread_specific<std::unordered_map<uint64_t, Sum>> local;
};

SkyWindows::SkyWindows(const SkyPortals& portals, const Bounds3f& bounds, double photon_power,
                       double estimate_power)
    : portals_(portals),
      bounds_(bounds),
      // A typical photon or estimate is about 2^20 units: sums of billions of records stay far
      // from 2^64, and a record a millionth as bright still counts.
      photon_to_fixed_(photon_power > 0 ? double(1 << 20) / photon_power : 1.0),
      estimate_to_fixed_(estimate_power > 0 ? double(1 << 20) / estimate_power : 1.0),
      pending_(std::make_unique<ThreadSums>()) {
    const Vec3f extent = bounds.max - bounds.min;
    const float longest = std::max({extent.x, extent.y, extent.z, 1e-6f});
    const float cell = longest / float(kCellsLongAxis);
    for (int a = 0; a < 3; ++a) {
        res_[a] = std::clamp(int(std::ceil(extent[a] / cell)), 1, kCellsLongAxis);
        inv_cell_[a] = float(res_[a]) / std::max(extent[a], 1e-6f);
    }
    // Windows: the portal triangles whose centroids share a cell, numbered in order of their first
    // triangle.
    const size_t n = portals.triangle_count();
    std::unordered_map<uint32_t, uint32_t> window_of_cell;
    triangle_window_.resize(n);
    std::vector<uint32_t> count;
    for (size_t t = 0; t < n; ++t) {
        const auto& v = portals.triangle(t);
        const uint32_t key = RegionKey((v[0] + v[1] + v[2]) / 3.f, 0);
        auto [it, added] = window_of_cell.try_emplace(key, uint32_t(count.size()));
        if (added) count.push_back(0);
        triangle_window_[t] = it->second;
        ++count[it->second];
    }
    const size_t windows = count.size();
    window_first_.assign(windows + 1, 0);
    for (size_t w = 0; w < windows; ++w) window_first_[w + 1] = window_first_[w] + count[w];
    window_triangles_.resize(n);
    std::vector<uint32_t> next(window_first_.begin(), window_first_.end() - 1);
    for (size_t t = 0; t < n; ++t) window_triangles_[next[triangle_window_[t]]++] = uint32_t(t);
    window_triangle_cdf_.resize(n);
    window_area_.assign(windows, 0.f);
    for (size_t w = 0; w < windows; ++w) {
        double area = 0;
        for (uint32_t k = window_first_[w]; k < window_first_[w + 1]; ++k) {
            area += portals.TriangleArea(window_triangles_[k]);
            window_triangle_cdf_[k] = float(area);
        }
        for (uint32_t k = window_first_[w]; k < window_first_[w + 1]; ++k)
            window_triangle_cdf_[k] = area > 0 ? float(window_triangle_cdf_[k] / area) : 1.f;
        window_area_[w] = float(area);
    }
}

SkyWindows::~SkyWindows() = default;

uint32_t SkyWindows::RegionKey(const Vec3f& p, int side) const {
    uint32_t c[3];
    for (int a = 0; a < 3; ++a) {
        const float x = (p[a] - bounds_.min[a]) * inv_cell_[a];
        if (!(x >= 0) || x >= float(res_[a]) + 1) return kNoRegion;
        c[a] = uint32_t(std::min(int(x), res_[a] - 1));
    }
    return ((c[2] * uint32_t(res_[1]) + c[1]) * uint32_t(res_[0]) + c[0]) * PathGuide::kSides +
           uint32_t(side);
}

void SkyWindows::RecordFixed(const Vec3f& p, int side, uint32_t triangle, double fixed) {
    const uint32_t region = RegionKey(p, side);
    if (region == kNoRegion || triangle >= triangle_window_.size() || !(fixed > 0)) return;
    const uint64_t key = (uint64_t(region) << 32) | triangle_window_[triangle];
    Sum& s = pending_->local.local()[key];
    s.fixed += uint64_t(std::llround(std::min(fixed, 1e15)));
    s.photons += 1;
}

Status SkyWindows::ShareRecords(
    const std::function<StatusOr<std::vector<std::byte>>(std::span<const std::byte>)>& gather) {
    struct Record {
        uint64_t key, fixed, photons;
    };
    std::vector<Record> mine;
    for (auto& local : pending_->local) {
        for (const auto& [key, s] : local) mine.push_back({key, s.fixed, s.photons});
        local.clear();
    }
    NAVE_ASSIGN_OR_RETURN(const std::vector<std::byte> all,
                          gather(std::as_bytes(std::span<const Record>(mine))));
    NAVE_ASSIGN_OR_RETURN(const std::vector<Record> records,
                          RecordsFromBytes<Record>(all, "sky window records from the processes"));
    auto& into = pending_->local.local();
    for (const Record& r : records) {
        Sum& s = into[r.key];
        s.fixed += r.fixed;
        s.photons += uint32_t(r.photons);
    }
    return Status::Ok();
}

void SkyWindows::Update() {
    for (auto& local : pending_->local) {
        for (const auto& [key, s] : local) {
            Sum& total = sums_[key];
            total.fixed += s.fixed;
            total.photons += s.photons;
        }
        local.clear();
    }
    if (sums_.size() > kMaxPairs) Forget(sums_.size() - kMaxPairs * 3 / 4);
    // Every region's windows in window order (the map's order is not the same on every run, the
    // choice must be).
    const std::vector<std::pair<uint64_t, Sum>> sums = SortedSums();
    regions_.clear();
    choice_window_.clear();
    choice_probability_.clear();
    choice_cdf_.clear();
    for (size_t i = 0; i < sums.size();) {
        const uint32_t region = uint32_t(sums[i].first >> 32);
        size_t j = i;
        uint64_t photons = 0;
        double total = 0;
        for (; j < sums.size() && uint32_t(sums[j].first >> 32) == region; ++j) {
            photons += sums[j].second.photons;
            total += double(sums[j].second.fixed);
        }
        if (photons >= kMinPhotons && total > 0) {
            Region r{uint32_t(choice_window_.size()), uint32_t(j - i)};
            double cdf = 0;
            for (size_t k = i; k < j; ++k) {
                const double p = double(sums[k].second.fixed) / total;
                cdf += p;
                choice_window_.push_back(uint32_t(sums[k].first & 0xffffffffu));
                choice_probability_.push_back(float(p));
                choice_cdf_.push_back(float(cdf));
            }
            choice_cdf_.back() = 1.f;
            regions_.emplace(region, r);
        }
        i = j;
    }
}

std::vector<std::pair<uint64_t, SkyWindows::Sum>> SkyWindows::SortedSums() const {
    std::vector<std::pair<uint64_t, Sum>> sorted(sums_.begin(), sums_.end());
    std::sort(sorted.begin(), sorted.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    return sorted;
}

void SkyWindows::Forget(size_t count) {
    std::vector<std::pair<uint32_t, uint64_t>> by_photons;  // (photons, key)
    by_photons.reserve(sums_.size());
    for (const auto& [key, s] : sums_) by_photons.emplace_back(s.photons, key);
    std::nth_element(by_photons.begin(), by_photons.begin() + ptrdiff_t(count), by_photons.end());
    for (size_t i = 0; i < count; ++i) sums_.erase(by_photons[i].second);
}

const SkyWindows::Region* SkyWindows::Find(const Vec3f& p, int side) const {
    const uint32_t key = RegionKey(p, side);
    if (key == kNoRegion) return nullptr;
    auto it = regions_.find(key);
    return it == regions_.end() ? nullptr : &it->second;
}

Vec3f SkyWindows::SamplePoint(const Region& region, float u_window, Point2f u) const {
    const float* cdf = choice_cdf_.data() + region.first;
    size_t k = size_t(std::upper_bound(cdf, cdf + region.count, u_window) - cdf);
    k = std::min<size_t>(k, region.count - 1);
    // What is left of u_window within the window's share picks its triangle.
    const float below = k > 0 ? cdf[k - 1] : 0.f;
    const float p = choice_probability_[region.first + k];
    const float u_triangle = p > 0 ? std::clamp((u_window - below) / p, 0.f, 1.f) : 0.f;
    const uint32_t w = choice_window_[region.first + k];
    const float* tcdf = window_triangle_cdf_.data() + window_first_[w];
    const size_t n = window_first_[w + 1] - window_first_[w];
    size_t t = size_t(std::upper_bound(tcdf, tcdf + n, u_triangle) - tcdf);
    t = std::min(t, n - 1);
    const auto& v = portals_.triangle(window_triangles_[window_first_[w] + t]);
    const std::array<float, 3> b = SampleUniformTriangle(u);
    return v[0] * b[0] + v[1] * b[1] + v[2] * b[2];
}

float SkyWindows::AreaDensity(const Region& region, uint32_t triangle) const {
    if (triangle >= triangle_window_.size()) return 0;
    const uint32_t w = triangle_window_[triangle];
    const uint32_t* first = choice_window_.data() + region.first;
    const uint32_t* last = first + region.count;
    const uint32_t* it = std::lower_bound(first, last, w);
    if (it == last || *it != w || !(window_area_[w] > 0)) return 0;
    return choice_probability_[region.first + size_t(it - first)] / window_area_[w];
}

uint64_t SkyWindows::MemoryBytes() const {
    // Hash map nodes of about 40 bytes and 8-byte buckets; the choice tables.
    return sums_.size() * 48 + regions_.size() * 40 +
           choice_window_.size() * (sizeof(uint32_t) + 2 * sizeof(float)) +
           triangle_window_.size() * 3 * sizeof(uint32_t) + window_area_.size() * 8;
}

void SkyWindows::SaveState(ByteWriter* out) const {
    const std::vector<std::pair<uint64_t, Sum>> sums = SortedSums();
    out->Put(uint64_t(sums.size()));
    for (const auto& [key, s] : sums) {
        out->Put(key);
        out->Put(s.fixed);
        out->Put(s.photons);
    }
}

Status SkyWindows::LoadState(ByteReader* in) {
    uint64_t n = 0;
    NAVE_RETURN_IF_ERROR(in->Get(&n, "sky window sum count"));
    sums_.clear();
    for (uint64_t i = 0; i < n; ++i) {
        uint64_t key = 0;
        Sum s;
        NAVE_RETURN_IF_ERROR(in->Get(&key, "sky window sum key"));
        NAVE_RETURN_IF_ERROR(in->Get(&s.fixed, "sky window sum"));
        NAVE_RETURN_IF_ERROR(in->Get(&s.photons, "sky window photon count"));
        if ((key & 0xffffffffu) >= window_area_.size()) {
            return DataLossError("{}: sky window {} of {}", in->what(), key & 0xffffffffu,
                                 window_area_.size());
        }
        sums_[key] = s;
    }
    Update();
    return Status::Ok();
}

}  // namespace nave::render
