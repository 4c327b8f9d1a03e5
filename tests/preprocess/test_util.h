#pragma once
// Helpers shared by the preprocess tests.

#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/triangle_source.h"

namespace nave::preprocess::testing {

inline std::filesystem::path Fixture(const std::string& name) {
    return std::filesystem::path(NAVE_TEST_FIXTURES) / "models" / name;
}

/// Opens `path` with OpenModel and reads every triangle; fails the test on error.
std::vector<Triangle> ReadModel(const std::filesystem::path& path,
                                std::unique_ptr<TriangleSource>* keep = nullptr);

/// The error message of opening and reading `path` completely ("" if it succeeded).
std::string ReadError(const std::filesystem::path& path);

/// A fresh empty directory under the system temp dir, removed by the caller.
std::filesystem::path MakeTempDir(const std::string& tag);

}  // namespace nave::preprocess::testing
