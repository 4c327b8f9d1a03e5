// The importers on the real models of ../shared/data/models: triangle counts must equal the table
// in its README.md. Skipped (with a message) where that directory is absent.

#include <gtest/gtest.h>

#include "test_util.h"

namespace nave::preprocess {
namespace {

std::filesystem::path Shared(const std::string& rel) {
    return std::filesystem::path(NAVE_SHARED_DATA) / "models" / rel;
}

void ExpectCount(const std::string& rel, size_t expected) {
    auto path = Shared(rel);
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << path << " absent (NAVE_SHARED_DATA): skipping";
    std::unique_ptr<TriangleSource> source;
    auto tris = testing::ReadModel(path, &source);
    EXPECT_EQ(tris.size(), expected) << rel;
    for (const auto& w : source->warnings().Summary())
        std::printf("  %s: %s\n", rel.c_str(), w.c_str());
}

TEST(SharedModels, Bunny) { ExpectCount("scans/bun_zipper.ply", 69451); }
TEST(SharedModels, Igea) { ExpectCount("scans/igea.ply", 268686); }
TEST(SharedModels, Dragon) { ExpectCount("scans/stanford-dragon-100k.obj", 100000); }
TEST(SharedModels, Armadillo) { ExpectCount("scans/armadillo.obj", 99976); }
TEST(SharedModels, Sponza) { ExpectCount("sponza/sponza_merged.obj", 236809); }
TEST(SharedModels, Helmet) { ExpectCount("gltf-helmet/DamagedHelmet.gltf", 15452); }

}  // namespace
}  // namespace nave::preprocess

namespace nave::preprocess {
namespace {

// Counts from README.md ("285 to 3,732") and, per file, from the file itself read independently of
// the importer: a binary STL's header count, an ASCII STL's number of "facet normal" lines.
TEST(SharedModels, StlFiles) {
    struct Case {
        const char* file;
        size_t facets;
    };
    const Case cases[] = {{"stl/3DSMaxExport.STL", 2000},
                          {"stl/Spider_ascii.stl", 1368},
                          {"stl/Spider_binary.stl", 1368},
                          {"stl/Wuson.stl", 3732},
                          {"stl/sphereWithHole.stl", 285}};
    for (const Case& c : cases) {
        auto path = Shared(c.file);
        if (!std::filesystem::exists(path))
            GTEST_SKIP() << path << " absent (NAVE_SHARED_DATA): skipping";
        std::unique_ptr<TriangleSource> source;
        auto tris = testing::ReadModel(path, &source);
        EXPECT_EQ(tris.size() + source->warnings().Total(), c.facets) << c.file;
    }
}

}  // namespace
}  // namespace nave::preprocess
