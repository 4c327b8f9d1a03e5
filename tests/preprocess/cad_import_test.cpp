// STEP and IGES through Open CASCADE (preprocess/import/cad_importer.h): a small assembly written
// by the test itself comes back in metres with its names, colours and placements, tessellated
// within the deflection nave asks for, wound outward; damaged files are errors naming them.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include "cad_fixtures.h"
#include "common/run_nave.h"
#include "common/scratch_dir.h"
#include "preprocess/import/cad_plugin.h"
#include "preprocess/import/importer.h"

namespace nave::preprocess {
namespace {

struct ReadBack {
    std::vector<Triangle> triangles;
    std::vector<store::MaterialRecord> materials;
    std::string units;
};

ReadBack Read(const std::filesystem::path& path, double precision = 0) {
    ReadBack out;
    StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(path, precision);
    EXPECT_TRUE(source.ok()) << source.status().ToString();
    if (!source.ok()) return out;
    StatusOr<std::vector<Triangle>> all = ReadAll(**source);
    EXPECT_TRUE(all.ok()) << all.status().ToString();
    if (all.ok()) out.triangles = std::move(*all);
    out.materials = (*source)->materials();
    out.units = (*source)->units();
    return out;
}

uint32_t MaterialNamed(const ReadBack& r, const std::string& name) {
    for (size_t i = 0; i < r.materials.size(); ++i) {
        if (r.materials[i].name == name) return uint32_t(i);
    }
    ADD_FAILURE() << "no material " << name;
    return ~0u;
}

Vec3d Centroid(const Triangle& t) { return (Vec3d(t.p[0]) + Vec3d(t.p[1]) + Vec3d(t.p[2])) / 3.0; }
Vec3d GeometricNormal(const Triangle& t) {
    return Normalize(Cross(Vec3d(t.p[1]) - Vec3d(t.p[0]), Vec3d(t.p[2]) - Vec3d(t.p[0])));
}
double Area(const Triangle& t) {
    return 0.5 * Length(Cross(Vec3d(t.p[1]) - Vec3d(t.p[0]), Vec3d(t.p[2]) - Vec3d(t.p[0])));
}

class CadImport : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!CadPluginBuilt()) GTEST_SKIP() << "nave was built without Open CASCADE";
    }
    test::ScratchDir dir_{"cad"};
};

TEST_F(CadImport, StepAssemblyComesBackInMetresWithNamesColoursAndPlacements) {
    const auto step = dir_ / "chapel.step";
    ASSERT_TRUE(testing::WriteChapelStep(step, "MM"));
    const ReadBack r = Read(step);
    EXPECT_EQ(r.units, "m");
    ASSERT_EQ(r.materials.size(), 2u);
    const uint32_t altar = MaterialNamed(r, "Altar");
    const uint32_t column = MaterialNamed(r, "Column");
    ASSERT_NE(altar, ~0u);
    EXPECT_NEAR(r.materials[altar].diffuse[0], 0.8f, 1e-3);
    EXPECT_NEAR(r.materials[altar].diffuse[1], 0.1f, 1e-3);
    EXPECT_NEAR(r.materials[altar].diffuse[2], 0.1f, 1e-3);

    Bounds3d bounds;
    double altar_area = 0;
    uint64_t altar_triangles = 0, east = 0, north = 0;
    for (const Triangle& t : r.triangles) {
        for (const Vec3f& p : t.p) bounds.Extend(Vec3d(p));
        if (t.material == altar) {
            ++altar_triangles;
            altar_area += Area(t);
        } else if (t.material == column) {
            (Centroid(t).x > 2.5 ? east : north) += 1;
        }
    }
    // A box is six rectangles: 12 triangles, whatever the deflection.
    EXPECT_EQ(altar_triangles, 12u);
    EXPECT_NEAR(altar_area, 2 * (1 * 2 + 1 * 0.5 + 2 * 0.5), 1e-5);
    // One part placed twice: the same triangles at both places.
    EXPECT_GT(east, 0u);
    EXPECT_EQ(east, north);
    const double r_col = testing::kColumnRadius;
    EXPECT_NEAR(bounds.min.x, -r_col, 1e-5);
    EXPECT_NEAR(bounds.min.y, -r_col, 1e-5);
    EXPECT_NEAR(bounds.min.z, 0, 1e-5);
    EXPECT_NEAR(bounds.max.x, 5 + r_col, 1e-5);
    EXPECT_NEAR(bounds.max.y, 5 + r_col, 1e-5);
    EXPECT_NEAR(bounds.max.z, 1, 1e-5);
}

// Every triangle is wound counter-clockwise seen from outside, and its shading normals agree.
TEST_F(CadImport, TrianglesFaceOutward) {
    const auto step = dir_ / "chapel.step";
    ASSERT_TRUE(testing::WriteChapelStep(step));
    const ReadBack r = Read(step);
    const uint32_t altar = MaterialNamed(r, "Altar");
    ASSERT_FALSE(r.triangles.empty());
    for (const Triangle& t : r.triangles) {
        const Vec3d n = GeometricNormal(t);
        const Vec3d c = Centroid(t);
        Vec3d outward;
        if (t.material == altar) {
            outward = c - Vec3d(0.5, 1, 0.25);
        } else {
            const Vec3d axis = c.x > 2.5 ? Vec3d(5, 0, c.z) : Vec3d(0, 5, c.z);
            // A cap faces along z; the side away from the axis.
            outward = std::abs(n.z) > 0.9 ? Vec3d(0, 0, c.z - 0.5) : c - axis;
        }
        EXPECT_GT(Dot(n, outward), 0) << "triangle at " << c.x << " " << c.y << " " << c.z;
        if (t.has_normals) {
            for (const Vec3f& s : t.n) EXPECT_GT(Dot(Vec3d(s), n), 0);
        }
    }
}

// The column's side lies within the linear deflection of the cylinder: every vertex on it, every
// triangle's centre at most the deflection inside (cad_plugin.h: 256 grid steps).
TEST_F(CadImport, TessellationStaysWithinTheDeflectionPrecisionAsks) {
    const auto step = dir_ / "chapel.step";
    ASSERT_TRUE(testing::WriteChapelStep(step));
    std::map<double, uint64_t> side_triangles;
    for (const double precision : {0.0, 1e-6, 1e-4}) {
        SCOPED_TRACE(precision);
        const ReadBack r = Read(step, precision);
        const uint32_t column = MaterialNamed(r, "Column");
        const double diagonal = std::sqrt(5.2 * 5.2 * 2 + 1);
        const double deflection =
            kDeflectionGridSteps * (precision > 0 ? precision : diagonal / double(1 << 20));
        uint64_t sides = 0;
        for (const Triangle& t : r.triangles) {
            if (t.material != column || std::abs(GeometricNormal(t).z) > 0.5) continue;
            const Vec3d c = Centroid(t);
            const Vec3d axis = c.x > 2.5 ? Vec3d(5, 0, 0) : Vec3d(0, 5, 0);
            for (const Vec3f& p : t.p) {
                EXPECT_NEAR(std::hypot(p.x - axis.x, p.y - axis.y), testing::kColumnRadius, 1e-5);
            }
            // A side triangle's centre is as far in as the middle of its chord, a third of the
            // way: within the deflection of the surface.
            const double inside = testing::kColumnRadius - std::hypot(c.x - axis.x, c.y - axis.y);
            EXPECT_GE(inside, -1e-5);
            EXPECT_LE(inside, deflection + 1e-6);
            ++sides;
        }
        side_triangles[precision] = sides;
        // 20 degrees of angular deflection: at least 18 sides around, two triangles each.
        EXPECT_GE(sides, 2u * 18 * 2);
    }
    EXPECT_GT(side_triangles[1e-6], side_triangles[0.0]);
}

TEST_F(CadImport, TheFilesLengthUnitIsApplied) {
    const auto mm = dir_ / "mm.step";
    const auto inch = dir_ / "inch.stp";
    const auto metre = dir_ / "m.STEP";
    ASSERT_TRUE(testing::WriteChapelStep(mm, "MM"));
    ASSERT_TRUE(testing::WriteChapelStep(inch, "INCH"));
    ASSERT_TRUE(testing::WriteChapelStep(metre, "M"));
    for (const auto& path : {mm, inch, metre}) {
        SCOPED_TRACE(path.filename().string());
        Bounds3d bounds;
        for (const Triangle& t : Read(path).triangles) {
            for (const Vec3f& p : t.p) bounds.Extend(Vec3d(p));
        }
        EXPECT_NEAR(bounds.max.x, 5 + testing::kColumnRadius, 1e-4);
        EXPECT_NEAR(bounds.max.z, 1, 1e-4);
    }
}

TEST_F(CadImport, IgesComesBackInMetresWithItsColours) {
    const auto iges = dir_ / "chapel.igs";
    ASSERT_TRUE(testing::WriteChapelIges(iges));
    const ReadBack r = Read(iges);
    EXPECT_EQ(r.units, "m");
    Bounds3d bounds;
    double red_area = 0;
    for (const Triangle& t : r.triangles) {
        for (const Vec3f& p : t.p) bounds.Extend(Vec3d(p));
        const store::MaterialRecord& m = r.materials.at(t.material);
        if (std::abs(m.diffuse[0] - 0.8f) < 1e-3 && std::abs(m.diffuse[1] - 0.1f) < 1e-3) {
            red_area += Area(t);
        }
    }
    EXPECT_NEAR(bounds.max.x, 5 + testing::kColumnRadius, 1e-4);
    EXPECT_NEAR(bounds.max.y, 5 + testing::kColumnRadius, 1e-4);
    EXPECT_NEAR(bounds.max.z, 1, 1e-4);
    // The altar's faces keep its red.
    EXPECT_NEAR(red_area, 7, 1e-4);
}

// Parts are handed over one at a time: after the first triangle, the source holds one part's
// mesh, not the model's.
TEST_F(CadImport, PartsStreamOneAtATime) {
    const auto step = dir_ / "chapel.step";
    ASSERT_TRUE(testing::WriteChapelStep(step));
    StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(step);
    ASSERT_TRUE(source.ok()) << source.status().ToString();
    const uint64_t total = (*source)->progress_total();
    std::vector<Triangle> batch;
    StatusOr<bool> more = (*source)->Next(batch, 1);
    ASSERT_TRUE(more.ok() && *more) << more.status().ToString();
    EXPECT_GT((*source)->memory_bytes(), 0u);
    // A mesh's bytes per triangle are at most 3 corners of position and normal (24 bytes each)
    // plus 12 bytes of indices: the three parts would take more than one.
    const uint64_t largest_part = total / 3 * 2;
    EXPECT_LE((*source)->memory_bytes(), largest_part * (3 * 24 + 12));
    EXPECT_EQ((*source)->progress_unit(), "triangles");
}

TEST_F(CadImport, DamagedFilesAreErrorsNamingThem) {
    const auto step = dir_ / "chapel.step";
    ASSERT_TRUE(testing::WriteChapelStep(step));
    std::string text;
    {
        std::ifstream in(step, std::ios::binary);
        text.assign(std::istreambuf_iterator<char>(in), {});
    }
    struct Case {
        std::string name, bytes;
    };
    const std::vector<Case> cases = {
        {"garbage.step", "this is not a STEP file\n"},
        {"header_only.stp", "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\nENDSEC;\nEND-ISO-10303-21;\n"},
        {"cut.step", text.substr(0, text.size() / 2)},
        // Cut at the end of an entity, where a reader could stop content with part of a model.
        {"cut_at_entity.step", text.substr(0, text.find("\n#100 =") + 1)},
        {"cut_after_data.step", text.substr(0, text.find("ENDSEC;", text.find("DATA;")) + 8)},
        {"garbage.iges", std::string(400, 'x')},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const auto path = dir_ / c.name;
        std::ofstream(path, std::ios::binary) << c.bytes;
        StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(path);
        Status status = source.status();
        if (source.ok()) status = ReadAll(**source).status();
        ASSERT_FALSE(status.ok());
        EXPECT_NE(status.message().find(path.string()), std::string::npos) << status.message();
        EXPECT_EQ(status.code(), StatusCode::kDataLoss) << status.message();
    }
}

// Open CASCADE 7.6 dereferences null on a vertex that names an entity of the wrong type (found by
// fuzz_cad): the crash ends the child that reads the file, and nave reports it naming the file and
// the signal, without a store.
TEST_F(CadImport, ACrashInOpenCascadeIsAnErrorNamingTheSignal) {
    std::string text;
    {
        std::ifstream in(std::filesystem::path(NAVE_TEST_FIXTURES) / "models/cad/chapel.step");
        text.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string vertex = "#83 = VERTEX_POINT('',#84);";
    const size_t at = text.find(vertex);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, vertex.size(), "#83 = VERTEX_POINT('',#27StepRepr_PropertyDefinition84);");
    const auto path = dir_ / "crash.step";
    std::ofstream(path, std::ios::binary) << text;
    StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(path);
    ASSERT_FALSE(source.ok());
    EXPECT_EQ(source.status().code(), StatusCode::kDataLoss);
    EXPECT_NE(source.status().message().find(path.string() + ": Open CASCADE crashed (signal 11"),
              std::string::npos)
        << source.status().message();
    const std::string out = (dir_ / "crash.nave").string();
    test::CommandResult run = test::RunNave("preprocess " + path.string() + " -o " + out);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

// The fuzz seeds (tests/fixtures/models/cad) are the chapel as the tests write it.
TEST_F(CadImport, CheckedInSeedsReadAsTheChapel) {
    const std::filesystem::path dir = std::filesystem::path(NAVE_TEST_FIXTURES) / "models" / "cad";
    for (const char* name : {"chapel.step", "chapel.igs"}) {
        SCOPED_TRACE(name);
        const ReadBack r = Read(dir / name);
        Bounds3d bounds;
        for (const Triangle& t : r.triangles) {
            for (const Vec3f& p : t.p) bounds.Extend(Vec3d(p));
        }
        EXPECT_GT(r.triangles.size(), 12u);
        EXPECT_NEAR(bounds.max.x, 5 + testing::kColumnRadius, 1e-4);
        EXPECT_NEAR(bounds.max.z, 1, 1e-4);
    }
}

TEST_F(CadImport, PreprocessTakesAStepFileAndRefusesADamagedOne) {
    const auto step = dir_ / "chapel.step";
    ASSERT_TRUE(testing::WriteChapelStep(step));
    const std::string out = (dir_ / "chapel.nave").string();
    test::CommandResult run = test::RunNave("preprocess " + step.string() + " -o " + out);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("STEP in millimetre, converted to metres"), std::string::npos)
        << run.output;
    test::CommandResult inspect = test::RunNave("inspect " + out);
    EXPECT_NE(inspect.output.find("Altar"), std::string::npos) << inspect.output;
    EXPECT_NE(inspect.output.find("Column"), std::string::npos) << inspect.output;

    const auto bad = dir_ / "bad.step";
    std::ofstream(bad) << "ISO-10303-21;\nHEADER;\nnonsense\n";
    const std::string bad_out = (dir_ / "bad.nave").string();
    run = test::RunNave("preprocess " + bad.string() + " -o " + bad_out);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find(bad.string()), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(bad_out));
}

}  // namespace
}  // namespace nave::preprocess
