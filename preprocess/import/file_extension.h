#pragma once
// A model file's extension as the importers compare it: ".STEP" and ".step" are one format.

#include <cctype>
#include <filesystem>
#include <string>

namespace nave::preprocess {

/// The extension of `path`, dot included, in lower case ("" when it has none).
inline std::string LowerExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace nave::preprocess
