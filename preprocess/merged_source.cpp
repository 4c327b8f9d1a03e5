#include "preprocess/merged_source.h"

#include <fmt/format.h>

namespace nave::preprocess {

MergedSource::MergedSource(std::vector<std::unique_ptr<TriangleSource>> sources)
    : sources_(std::move(sources)),
      remap_(sources_.size()),
      finished_progress_(sources_.size(), 0) {}

uint32_t MergedSource::GlobalMaterial(size_t source, uint32_t local) {
    std::vector<int64_t>& remap = remap_[source];
    if (local >= remap.size()) remap.resize(local + 1, -1);
    if (remap[local] < 0) {
        store::MaterialRecord m = sources_[source]->materials().at(local);
        std::string base = m.name.empty() ? "material" : m.name;
        std::string name = base;
        for (int k = 1; names_.count(name) != 0; ++k) name = fmt::format("{}.{}", base, k);
        names_.insert(name);
        m.name = name;
        materials_.push_back(std::move(m));
        remap[local] = int64_t(materials_.size() - 1);
    }
    return uint32_t(remap[local]);
}

void MergedSource::AddRemainingMaterials(size_t source) {
    // Materials no triangle used still go into the table (the user may map them in a render
    // config).
    for (uint32_t i = 0; i < sources_[source]->materials().size(); ++i) GlobalMaterial(source, i);
}

StatusOr<bool> MergedSource::Next(std::vector<Triangle>& batch, size_t max_triangles) {
    batch.clear();
    while (current_ < sources_.size()) {
        TriangleSource& source = *sources_[current_];
        NAVE_ASSIGN_OR_RETURN(bool more, source.Next(batch, max_triangles));
        if (more) {
            for (Triangle& t : batch) t.material = GlobalMaterial(current_, t.material);
            return true;
        }
        AddRemainingMaterials(current_);
        warnings_.Merge(source.warnings());
        finished_progress_[current_] = source.progress_total();
        ++current_;
    }
    return false;
}

std::string MergedSource::name() const {
    std::string out;
    for (const auto& s : sources_) out += (out.empty() ? "" : " + ") + s->name();
    return out;
}

std::string MergedSource::content() const {
    std::string content;
    for (const auto& s : sources_) {
        const std::string one = s->content();
        if (!one.empty()) content += (content.empty() ? "" : "|") + one;
    }
    return content;
}

std::string MergedSource::units() const {
    std::string units;
    for (const auto& s : sources_) {
        if (units.empty())
            units = s->units();
        else if (units != s->units())
            return "mixed";
    }
    return units.empty() ? "unknown" : units;
}

uint64_t MergedSource::progress_done() const {
    uint64_t done = 0;
    for (size_t i = 0; i < sources_.size(); ++i) {
        done += i < current_ ? sources_[i]->progress_total()
                             : (i == current_ ? sources_[i]->progress_done() : 0);
    }
    return done;
}

std::string MergedSource::progress_unit() const {
    std::string unit = sources_.empty() ? "bytes" : sources_[0]->progress_unit();
    for (const auto& s : sources_) {
        if (s->progress_unit() != unit) return "units";
    }
    return unit;
}

uint64_t MergedSource::progress_total() const {
    uint64_t total = 0;
    for (const auto& s : sources_) total += s->progress_total();
    return total;
}

uint64_t MergedSource::memory_bytes() const {
    uint64_t bytes = 0;
    for (const auto& s : sources_) bytes += s->memory_bytes();
    return bytes;
}

}  // namespace nave::preprocess
