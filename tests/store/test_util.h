#pragma once
// Helpers shared by the store tests: a scratch directory and triangle keys that compare meshes as
// sets of oriented triangles on the store's grid.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "store/brick_mesh.h"
#include "store/grid.h"
#include "store/store_reader.h"

namespace nave::store::test {

/// Writes `bytes` to `path` (replacing it) and opens it as a store: for tests of damaged stores.
inline StatusOr<std::unique_ptr<Store>> OpenStoreBytes(const std::filesystem::path& path,
                                                       const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    return Store::Open(path);
}

/// A fresh directory under the system's temporary directory, removed with everything in it.
class ScratchDir {
  public:
    ScratchDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name =
            info ? std::string(info->test_suite_name()) + "." + info->name() : "nave";
        std::replace(name.begin(), name.end(), '/', '_');
        path_ = std::filesystem::temp_directory_path() /
                ("nave_store_test_" + std::to_string(::getpid()) + "_" + name);
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
    /// Names of the files in the directory.
    std::vector<std::string> Files() const {
        std::vector<std::string> out;
        for (const auto& e : std::filesystem::directory_iterator(path_))
            out.push_back(e.path().filename().string());
        std::sort(out.begin(), out.end());
        return out;
    }

  private:
    std::filesystem::path path_;
};

/// A triangle as its three grid points, rotated so the smallest comes first (orientation kept),
/// plus its material.
using TriangleKey = std::tuple<std::array<std::array<int32_t, 3>, 3>, uint32_t>;

inline std::array<int32_t, 3> GridKey(const GlobalGrid& grid, const Vec3f& p) {
    const Vec3i q = grid.Quantize(p);
    return {q.x, q.y, q.z};
}

inline TriangleKey KeyOf(const BrickMesh& mesh, size_t t, const GlobalGrid& grid) {
    std::array<std::array<int32_t, 3>, 3> c;
    for (int k = 0; k < 3; ++k) c[k] = GridKey(grid, mesh.positions[mesh.indices[3 * t + k]]);
    const int first = int(std::min_element(c.begin(), c.end()) - c.begin());
    std::rotate(c.begin(), c.begin() + first, c.end());
    return {c, mesh.material_ids[t]};
}

/// Keys of every triangle of `mesh` whose corners land on three distinct grid points, sorted.
inline std::vector<TriangleKey> SortedKeys(const BrickMesh& mesh, const GlobalGrid& grid,
                                           bool skip_degenerate) {
    std::vector<TriangleKey> keys;
    for (size_t t = 0; t < mesh.TriangleCount(); ++t) {
        TriangleKey k = KeyOf(mesh, t, grid);
        const auto& c = std::get<0>(k);
        if (skip_degenerate && (c[0] == c[1] || c[1] == c[2] || c[0] == c[2])) continue;
        keys.push_back(k);
    }
    std::sort(keys.begin(), keys.end());
    return keys;
}

}  // namespace nave::store::test
