#include "test_util.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include "preprocess/import/importer.h"

namespace nave::preprocess::testing {

std::vector<Triangle> ReadModel(const std::filesystem::path& path,
                                std::unique_ptr<TriangleSource>* keep) {
    auto source = OpenModel(path);
    EXPECT_TRUE(source.ok()) << source.status().ToString();
    if (!source.ok()) return {};
    auto all = ReadAll(**source);
    EXPECT_TRUE(all.ok()) << all.status().ToString();
    if (keep != nullptr) *keep = std::move(*source);
    return all.ok() ? *all : std::vector<Triangle>{};
}

std::string ReadError(const std::filesystem::path& path) {
    auto source = OpenModel(path);
    if (!source.ok()) return source.status().ToString();
    auto all = ReadAll(**source);
    return all.ok() ? std::string() : all.status().ToString();
}

std::filesystem::path MakeTempDir(const std::string& tag) {
    static int counter = 0;
    auto dir =
        std::filesystem::temp_directory_path() /
        ("nave_test_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace nave::preprocess::testing
