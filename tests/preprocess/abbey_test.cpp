// The procedural abbey: deterministic, the material names every render config maps, the size of the
// church, consistent normals, detail that scales the triangle count, and streaming in constant
// memory.

#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/abbey_source.h"
#include "preprocess/abbey/glass_textures.h"
#include "preprocess/abbey/materials.h"
#include "preprocess/abbey/primitives.h"
#include "src/core/spectrum.h"
#include "src/core/spectrum_data.h"
#include "src/imaging/image_io.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using testing::AbbeyDigest;
using testing::DigestOf;

TEST(Abbey, PointedArchProfile) {
    // Crown at t = 0, springing at t = 1; the equilateral arch (rho = 2) rises sqrt(3) half-spans:
    // at t = 0.5 its height is sqrt(4 - 1.5^2) / sqrt(3) of the rise.
    EXPECT_DOUBLE_EQ(abbey::PointedArch(0, 2), 1.0);
    EXPECT_NEAR(abbey::PointedArch(1, 2), 0.0, 1e-12);
    EXPECT_NEAR(abbey::PointedArch(0.5, 2), std::sqrt(4 - 2.25) / std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(abbey::PointedArch(0.5, 1), std::sqrt(0.75), 1e-12);  // round arch: a circle
}

TEST(Abbey, DeterministicWithTheAgreedMaterialsAndSize) {
    auto a = MakeAbbeySource(0.25);
    auto b = MakeAbbeySource(0.25);
    AbbeyDigest da = DigestOf(*a), db = DigestOf(*b);
    EXPECT_EQ(da.triangles, db.triangles);
    EXPECT_EQ(da.hash, db.hash) << "same detail must give the same triangles";
    std::vector<std::string> names;
    for (const auto& m : a->materials()) names.push_back(m.name);
    EXPECT_THAT(
        names, ::testing::ElementsAre("limestone", "limestone_dark", "floor_tile_light",
                                      "floor_tile_dark", "glass_clear", "glass_blue", "glass_red",
                                      "glass_yellow", "glass_green", "lead", "wood", "roof_slate"));
    for (size_t m = 0; m < da.per_material.size(); ++m)
        EXPECT_GT(da.per_material[m], 0u) << names[m];
    // About 100 m long east-west, apse to the east (+x), ridge near 39 m, floor at 0.
    EXPECT_GT(da.bounds.max.x - da.bounds.min.x, 95.0);
    EXPECT_LT(da.bounds.max.x - da.bounds.min.x, 110.0);
    EXPECT_GT(da.bounds.max.x, 95.0);
    EXPECT_NEAR(da.bounds.min.z, 0.0, 1e-3);
    EXPECT_GT(da.bounds.max.z, 38.0);
    EXPECT_LT(da.bounds.max.z, 45.0);
    EXPECT_EQ(a->units(), "m");
    EXPECT_GT(da.with_normals, 0u);
    EXPECT_EQ(da.bad_normals, 0u);
}

TEST(Abbey, ParallelProducersGiveTheSameTrianglesInTheSameOrder) {
    // Parts generated on several threads are handed on in the plan's order: the stream (count, and
    // a hash of every triangle in order) is the one thread's.
    const AbbeyDigest one = DigestOf(*MakeAbbeySource(0.5, 1));
    for (int threads : {2, 3, 8}) {
        const AbbeyDigest many = DigestOf(*MakeAbbeySource(0.5, threads));
        EXPECT_EQ(many.triangles, one.triangles) << threads << " threads";
        EXPECT_EQ(many.hash, one.hash) << threads << " threads";
        EXPECT_EQ(many.per_material, one.per_material) << threads << " threads";
    }
    EXPECT_GT(one.triangles, 100000u);
}

TEST(Abbey, AStopBeforeTheEndJoinsEveryProducer) {
    // Destroyed after one batch, with producers blocked on full parts: no hang, no leak.
    auto source = MakeAbbeySource(1.0, 4);
    std::vector<Triangle> batch;
    ASSERT_TRUE(*source->Next(batch, 1000));
    EXPECT_EQ(batch.size(), 1000u);
    source.reset();
}

TEST(Abbey, PlanContainsNaveChoirChapelsNotOutside) {
    EXPECT_TRUE(abbey::InsidePlan(28, 0));      // nave
    EXPECT_TRUE(abbey::InsidePlan(28, 10));     // north aisle
    EXPECT_TRUE(abbey::InsidePlan(62, 24));     // north transept arm
    EXPECT_TRUE(abbey::InsidePlan(90, 0));      // apse
    EXPECT_TRUE(abbey::InsidePlan(83 + 9, 5));  // ambulatory
    EXPECT_TRUE(abbey::InsidePlan(98, 0));      // axial chapel
    EXPECT_FALSE(abbey::InsidePlan(28, 20));    // beside the aisle
    EXPECT_FALSE(abbey::InsidePlan(-5, 0));     // west of the facade
    EXPECT_FALSE(abbey::InsidePlan(75, 20));    // east of the transept, north of the choir aisle
}

TEST(Abbey, GeneratorSpecErrors) {
    EXPECT_TRUE(OpenGenerator("abbey").ok());
    EXPECT_TRUE(OpenGenerator("abbey:detail=0.5").ok());
    EXPECT_THAT(OpenGenerator("castle").status().message(), ::testing::HasSubstr("unknown"));
    EXPECT_THAT(OpenGenerator("abbey:detail=-1").status().message(),
                ::testing::HasSubstr("must be a number"));
    EXPECT_THAT(OpenGenerator("abbey:size=3").status().message(),
                ::testing::HasSubstr("expected detail=D"));
}

}  // namespace
}  // namespace nave::preprocess

namespace nave::preprocess {
namespace {

// Every glass pane carries texture coordinates across its window (origin top-left), and the glass
// materials name their spectral transmittance maps.
TEST(AbbeyGlass, PanesHaveWindowTextureCoordinatesAndMaterialsNameTheirMaps) {
    auto source = MakeAbbeySource(0.25);
    const auto& materials = source->materials();
    std::vector<Triangle> batch;
    uint64_t panes = 0, without_uv = 0, outside = 0;
    for (;;) {
        auto more = source->Next(batch, 1 << 16);
        ASSERT_TRUE(more.ok()) << more.status().ToString();
        if (!*more) break;
        for (const Triangle& t : batch) {
            if (materials[t.material].name.rfind("glass_", 0) != 0) continue;
            ++panes;
            without_uv += !t.has_uvs;
            for (const auto& uv : t.uv)
                outside +=
                    !(uv[0] >= -1e-5f && uv[0] <= 1.00001f && uv[1] >= -1e-5f && uv[1] <= 1.00001f);
        }
    }
    EXPECT_GT(panes, 100u);
    EXPECT_EQ(without_uv, 0u);
    EXPECT_EQ(outside, 0u);
    for (const char* name :
         {"glass_clear", "glass_blue", "glass_red", "glass_yellow", "glass_green"}) {
        auto it = std::find_if(materials.begin(), materials.end(),
                               [&](const auto& m) { return m.name == name; });
        ASSERT_NE(it, materials.end());
        EXPECT_EQ(it->textures.at(abbey::kTransmittanceSlot), abbey::GlassTextureName(name));
    }
}

// The maps: 21 bands 380-780 nm named in the header; the internal transmittance at 550 nm averages
// the value inverted from the CSV's total transmittance, T = (1-R)² τ / (1 - R² τ²) with R = 0.04,
// and varies with the glass's thickness (τ0^(1 ± 0.3)).
TEST(AbbeyGlass, TransmittanceMapsFollowTheGlassSpectra) {
    auto dir = testing::MakeTempDir("abbey_glass");
    ASSERT_TRUE(abbey::WriteGlassTextures(dir).ok());
    const SpectraTable& table = EmbeddedSpectraTable("stained_glass_approx.csv");
    for (const char* name : {"glass_clear", "glass_blue", "glass_red"}) {
        auto image = imaging::ReadImage(dir / abbey::GlassTextureName(name));
        ASSERT_TRUE(image.ok()) << image.status().ToString();
        ASSERT_EQ(image->channels.size(), 21u);
        const size_t band550 = (550 - 380) / 20;  // band 8 is centred on 540, 9 on 560: interpolate
        double sum540 = 0, sum560 = 0, lo = 1, hi = 0;
        const size_t n = size_t(image->width) * size_t(image->height);
        for (size_t p = 0; p < n; ++p) {
            const float v540 = image->pixels[p * 21 + band550],
                        v560 = image->pixels[p * 21 + band550 + 1];
            sum540 += v540;
            sum560 += v560;
            lo = std::min(lo, double(v560));
            hi = std::max(hi, double(v560));
        }
        const double mean550 = 0.5 * (sum540 + sum560) / double(n);
        const double total =
            0.5 * (table.ToSpectrum(name)->Evaluate(540) + table.ToSpectrum(name)->Evaluate(560));
        const double r = 0.04;
        // Check the inversion the other way: the pane with the mean τ has the CSV's total T
        // (Jensen's gap of τ0^(1 ± 0.3) and half-float storage allow a few per cent).
        const double total_back = (1 - r) * (1 - r) * mean550 / (1 - r * r * mean550 * mean550);
        EXPECT_NEAR(total_back, total, 0.04 * total + 2e-3) << name;
        if (total > 0.05 && total < 0.95) {
            EXPECT_GT(hi - lo, 0.01) << name << ": the thickness varies";
        }
    }
    // The band centres travel in the header.
    auto in = OIIO::ImageInput::open((dir / abbey::GlassTextureName("glass_blue")).string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().get_string_attribute(imaging::kBandCentresAttribute).substr(0, 12),
              "380,400,420,");
}

}  // namespace
}  // namespace nave::preprocess
