#pragma once
// What a test's directory holds, by name: the check that a failed or interrupted write left
// nothing behind and changed nothing.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace nave::test {

/// Every entry's file name in `dir`, sorted.
inline std::vector<std::string> ListNames(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace nave::test
