#include "test_util.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>

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

::nave::test::ScratchDir MakeTempDir(const std::string& tag) {
    return ::nave::test::ScratchDir("test_" + tag);
}

AbbeyDigest DigestOf(TriangleSource& source) {
    AbbeyDigest d;
    d.per_material.assign(source.materials().size(), 0);
    std::vector<Triangle> batch;
    while (true) {
        auto more = source.Next(batch, 5000);
        EXPECT_TRUE(more.ok());
        if (!more.ok() || !*more) break;
        for (const Triangle& t : batch) {
            ++d.triangles;
            ++d.per_material.at(t.material);
            for (const Vec3f& p : t.p) {
                d.bounds.Extend(Vec3d(p));
                uint32_t bits[3];
                std::memcpy(bits, &p, 12);
                for (uint32_t b : bits) d.hash = (d.hash ^ b) * 1099511628211ull;
            }
            if (t.has_normals) {
                ++d.with_normals;
                Vec3f g = Cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
                for (const Vec3f& n : t.n) {
                    // A shading normal on the back of its triangle would be a winding error.
                    if (!(Dot(n, g) > 0) || std::abs(Length(n) - 1) > 1e-3f) ++d.bad_normals;
                }
            }
        }
    }
    return d;
}

}  // namespace nave::preprocess::testing
