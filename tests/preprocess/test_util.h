#pragma once
// Helpers shared by the preprocess tests.

#include <filesystem>
#include <string>
#include <vector>

#include "common/scratch_dir.h"
#include "preprocess/triangle_source.h"
#include "src/core/vecmath.h"

namespace nave::preprocess::testing {

inline std::filesystem::path Fixture(const std::string& name) {
    return std::filesystem::path(NAVE_TEST_FIXTURES) / "models" / name;
}

/// A triangle's area, in double precision.
inline double Area(const Triangle& t) {
    const Vec3d a(t.p[0]), b(t.p[1]), c(t.p[2]);
    return 0.5 * Length(Cross(b - a, c - a));
}

/// Opens `path` with OpenModel and reads every triangle; fails the test on error.
std::vector<Triangle> ReadModel(const std::filesystem::path& path,
                                std::unique_ptr<TriangleSource>* keep = nullptr);

/// The error message of opening and reading `path` completely ("" if it succeeded).
std::string ReadError(const std::filesystem::path& path);

/// What a triangle stream holds, in a few numbers: counts, bounds, a hash of every position (FNV-1a
/// over the float bits, so two streams with equal digests are identical), and shading normals that
/// point to the back of their triangle or are not unit length (winding errors).
struct AbbeyDigest {
    uint64_t triangles = 0, with_normals = 0, bad_normals = 0;
    uint64_t hash = 1469598103934665603ull;
    Bounds3d bounds;
    std::vector<uint64_t> per_material;
};

/// Reads `source` to the end; fails the test on a read error.
AbbeyDigest DigestOf(TriangleSource& source);

/// A fresh empty directory under the system temp dir, removed when the returned object goes.
::nave::test::ScratchDir MakeTempDir(const std::string& tag);

}  // namespace nave::preprocess::testing
