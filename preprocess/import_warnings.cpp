#include "preprocess/import_warnings.h"

#include <fmt/format.h>

namespace nave::preprocess {

void ImportWarnings::Add(const std::string& what, const std::string& where) {
    Kind& kind = kinds_[what];
    if (kind.count++ == 0) kind.first = where;
}

void ImportWarnings::Merge(const ImportWarnings& other) {
    for (const auto& [what, kind] : other.kinds_) {
        Kind& mine = kinds_[what];
        if (mine.count == 0) mine.first = kind.first;
        mine.count += kind.count;
    }
}

uint64_t ImportWarnings::Count(const std::string& what) const {
    auto it = kinds_.find(what);
    return it == kinds_.end() ? 0 : it->second.count;
}

uint64_t ImportWarnings::Total() const {
    uint64_t total = 0;
    for (const auto& [what, kind] : kinds_) total += kind.count;
    return total;
}

std::vector<std::string> ImportWarnings::Summary() const {
    std::vector<std::string> lines;
    for (const auto& [what, kind] : kinds_) {
        lines.push_back(fmt::format("{}: {} (first at {})", what, kind.count, kind.first));
    }
    return lines;
}

}  // namespace nave::preprocess
