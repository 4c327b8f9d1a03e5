#include "src/core/spectrum_data.h"

#include <algorithm>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "src/core/check.h"

namespace nave {
namespace detail {
struct EmbeddedFile {
    std::string_view name;
    std::string_view text;
};
// Defined in the generated spectrum_data_embedded.cpp.
extern const EmbeddedFile kEmbeddedFiles[];
extern const std::size_t kNumEmbeddedFiles;
}  // namespace detail

std::string_view EmbeddedDataFile(std::string_view name) {
    for (std::size_t i = 0; i < detail::kNumEmbeddedFiles; ++i)
        if (detail::kEmbeddedFiles[i].name == name) return detail::kEmbeddedFiles[i].text;
    return {};
}

std::vector<std::string_view> EmbeddedDataFileNames() {
    std::vector<std::string_view> names;
    for (std::size_t i = 0; i < detail::kNumEmbeddedFiles; ++i)
        names.push_back(detail::kEmbeddedFiles[i].name);
    std::sort(names.begin(), names.end());
    return names;
}

const SpectraTable& EmbeddedSpectraTable(std::string_view name) {
    static std::mutex mutex;
    // unique_ptr keeps each table at a stable address while the map grows.
    static std::map<std::string, std::unique_ptr<SpectraTable>, std::less<>> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(name);
    if (it != cache.end()) return *it->second;
    std::string_view text = EmbeddedDataFile(name);
    NAVE_CHECK(!text.empty()) << "data file " << name << " is not compiled into nave";
    StatusOr<SpectraTable> table = ParseSpectraCsv(text, name);
    NAVE_CHECK(table.ok()) << "compiled-in data is malformed: " << table.status().ToString();
    auto [pos, inserted] =
        cache.emplace(std::string(name), std::make_unique<SpectraTable>(std::move(table).value()));
    return *pos->second;
}

}  // namespace nave
