// IFC 2x3 and IFC 4 through IFC++ (preprocess/import/ifc_plugin.h): the fixtures (a wall in
// millimetres with a window in its opening, and a room) come back in metres, the opening cut out of
// the wall, the window's pane as glazing, the room not rendered; damaged files are errors naming
// them.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>

#include "common/run_nave.h"
#include "common/scratch_dir.h"
#include "preprocess/import/ifc_plugin.h"
#include "preprocess/import/importer.h"

namespace nave::preprocess {
namespace {

std::filesystem::path IfcFixture(const std::string& name) {
    return std::filesystem::path(NAVE_TEST_FIXTURES) / "models" / "ifc" / name;
}

struct PerMaterial {
    uint64_t triangles = 0;
    double area = 0;
    double signed_volume = 0;  ///< of the closed surface, by the divergence theorem
    Bounds3d bounds;
};

struct IfcReadBack {
    std::map<std::string, PerMaterial> by_name;
    std::vector<store::MaterialRecord> materials;
    std::string units, content;
    Bounds3d bounds;
};

IfcReadBack Read(const std::filesystem::path& path) {
    IfcReadBack out;
    StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(path);
    EXPECT_TRUE(source.ok()) << source.status().ToString();
    if (!source.ok()) return out;
    StatusOr<std::vector<Triangle>> all = ReadAll(**source);
    EXPECT_TRUE(all.ok()) << all.status().ToString();
    out.materials = (*source)->materials();
    out.units = (*source)->units();
    out.content = (*source)->content();
    if (!all.ok()) return out;
    for (const Triangle& t : *all) {
        PerMaterial& m = out.by_name[out.materials.at(t.material).name];
        const Vec3d a(t.p[0]), b(t.p[1]), c(t.p[2]);
        ++m.triangles;
        m.area += 0.5 * Length(Cross(b - a, c - a));
        m.signed_volume += Dot(a, Cross(b, c)) / 6.0;
        for (const Vec3d& p : {a, b, c}) {
            m.bounds.Extend(p);
            out.bounds.Extend(p);
        }
    }
    return out;
}

class IfcImport : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!IfcPluginBuilt()) GTEST_SKIP() << "nave was built without IFC++";
    }
    test::ScratchDir dir_{"ifc"};
};

// Both schemas: the wall's entity type differs (IFC 2x3 writes IfcWallStandardCase), the rest is
// one model.
TEST_F(IfcImport, AWallWithAWindowComesBackInMetresWithItsOpeningCut) {
    for (const auto& [file, wall] :
         {std::pair{"wall_window_ifc4.ifc", "IfcWall:Limestone"},
          std::pair{"wall_window_ifc2x3.ifc", "IfcWallStandardCase:Limestone"}}) {
        SCOPED_TRACE(file);
        const IfcReadBack r = Read(IfcFixture(file));
        EXPECT_EQ(r.units, "m");
        ASSERT_EQ(r.by_name.size(), 3u);
        ASSERT_TRUE(r.by_name.count(wall));
        ASSERT_TRUE(r.by_name.count("IfcWindow glazing:Glass"));
        ASSERT_TRUE(r.by_name.count("IfcWindow:Oak"));
        // The wall, 4 x 0.2 x 3 m less the opening 1 x 0.2 x 1.2 m: its outside, the opening's
        // four reveals, and the volume they close, wound outward.
        const PerMaterial& w = r.by_name.at(wall);
        const double area = 2 * (4 * 3 + 4 * 0.2 + 3 * 0.2) - 2 * (1 * 1.2) + 2 * (1 + 1.2) * 0.2;
        EXPECT_NEAR(w.area, area, 1e-4);
        EXPECT_NEAR(w.signed_volume, 4 * 0.2 * 3 - 1 * 0.2 * 1.2, 1e-4);
        EXPECT_NEAR(w.bounds.min.x, -2, 1e-5);
        EXPECT_NEAR(w.bounds.max.z, 3, 1e-5);
        // The pane in the opening: 0.9 x 1.1 m from 1.05 m up, its placement chained through the
        // opening's and the wall's.
        const PerMaterial& pane = r.by_name.at("IfcWindow glazing:Glass");
        EXPECT_NEAR(pane.bounds.min.z, 1.05, 1e-5);
        EXPECT_NEAR(pane.bounds.max.z, 2.15, 1e-5);
        EXPECT_NEAR(pane.bounds.max.x - pane.bounds.min.x, 0.9, 1e-5);
        EXPECT_GT(pane.signed_volume, 0);
        // The room in front of the wall (y < -0.1) is not a surface.
        EXPECT_NEAR(r.bounds.min.y, -0.1, 1e-5);
    }
}

TEST_F(IfcImport, StylesGiveColoursAndTheGlazingIsTransparent) {
    const IfcReadBack r = Read(IfcFixture("wall_window_ifc4.ifc"));
    for (const store::MaterialRecord& m : r.materials) {
        if (m.name == "IfcWindow glazing:Glass") {
            EXPECT_NEAR(m.diffuse[2], 0.8f, 1e-5);
            // IFC's transparency 0.6: opacity 0.4.
            EXPECT_NEAR(m.opacity, 0.4f, 1e-5);
        } else if (m.name == "IfcWindow:Oak") {
            EXPECT_NEAR(m.diffuse[0], 0.4f, 1e-5);
            EXPECT_NEAR(m.opacity, 1.f, 1e-5);
        }
    }
    EXPECT_EQ(r.content.rfind("IFC4;unit=0.001m;IfcWall=", 0), 0u) << r.content;
    EXPECT_NE(r.content.find("IfcWindow="), std::string::npos) << r.content;
}

TEST_F(IfcImport, InspectShowsTheSchemaTheUnitAndTheEntityTypes) {
    const std::string out = (dir_ / "wall.nave").string();
    test::CommandResult run =
        test::RunNave("preprocess " + IfcFixture("wall_window_ifc2x3.ifc").string() + " -o " + out);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("IFC2X3 with a length unit of 0.001 m"), std::string::npos)
        << run.output;
    test::CommandResult inspect = test::RunNave("inspect " + out);
    EXPECT_NE(inspect.output.find("content      IFC2X3, length unit 0.001m; triangles by entity "
                                  "type: IfcWallStandardCase "),
              std::string::npos)
        << inspect.output;
}

TEST_F(IfcImport, DamagedFilesAreErrorsNamingThem) {
    std::string text;
    {
        std::ifstream in(IfcFixture("wall_window_ifc4.ifc"), std::ios::binary);
        text.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string header = text.substr(0, text.find("DATA;"));
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"garbage.ifc", "this is not IFC\n"},
        {"empty_data.ifc", header + "DATA;\nENDSEC;\nEND-ISO-10303-21;\n"},
        {"cut.ifc", text.substr(0, text.size() / 3)},
        // Cut at the end of an entity: it would parse, as part of the model.
        {"cut_at_entity.ifc", text.substr(0, text.find("#47="))},
    };
    for (const auto& [name, bytes] : cases) {
        SCOPED_TRACE(name);
        const auto path = dir_ / name;
        std::ofstream(path, std::ios::binary) << bytes;
        StatusOr<std::unique_ptr<TriangleSource>> source = OpenModel(path);
        Status status = source.status();
        if (source.ok()) status = ReadAll(**source).status();
        ASSERT_FALSE(status.ok());
        EXPECT_EQ(status.code(), StatusCode::kDataLoss) << status.message();
        EXPECT_NE(status.message().find(path.string()), std::string::npos) << status.message();
    }
    const std::string out = (dir_ / "garbage.nave").string();
    test::CommandResult run =
        test::RunNave("preprocess " + (dir_ / "garbage.ifc").string() + " -o " + out);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_FALSE(std::filesystem::exists(out));
}

// The mean of an image's RGB over all its pixels.
double MeanRgb(const std::filesystem::path& exr) {
    auto in = OIIO::ImageInput::open(exr.string());
    EXPECT_TRUE(in) << exr;
    if (!in) return -1;
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    double sum = 0;
    for (size_t i = 0; i < pixels.size(); i += size_t(spec.nchannels)) {
        sum += pixels[i] + pixels[i + 1] + pixels[i + 2];
    }
    return sum / double(3 * spec.width * spec.height);
}

// configs/ifc_chapel.toml renders the IFC building lit through its windows, its names mapped by
// pattern: the panes pass the sun and sky in; with the same panes black, the closed nave is dark.
TEST_F(IfcImport, TheChapelIsLitThroughItsWindowsByTheExampleConfig) {
    const std::string store = (dir_ / "chapel.nave").string();
    test::CommandResult run =
        test::RunNave("preprocess -q " + IfcFixture("chapel_ifc4.ifc").string() + " -o " + store);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const std::filesystem::path config =
        std::filesystem::path(NAVE_TEST_FIXTURES).parent_path().parent_path() / "configs" /
        "ifc_chapel.toml";
    std::string text;
    {
        std::ifstream in(config);
        text.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string glass = "builtin = \"window_glass\"";
    ASSERT_NE(text.find(glass), std::string::npos);
    std::string blind = text;
    blind.replace(blind.find(glass), glass.size(), "type = \"black\"");
    const auto blind_config = dir_ / "blind.toml";
    std::ofstream(blind_config) << blind;

    const std::string options = " --resolution 48x32 --spp 4 -q";
    run = test::RunNave("render " + store + " --config " + config.string() + " -o " +
                        (dir_ / "lit.exr").string() + options);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    run = test::RunNave("render " + store + " --config " + blind_config.string() + " -o " +
                        (dir_ / "blind.exr").string() + options);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const double lit = MeanRgb(dir_ / "lit.exr"), dark = MeanRgb(dir_ / "blind.exr");
    EXPECT_GT(lit, 0);
    // Black panes leave nothing but what the nave's surfaces emit: none.
    EXPECT_EQ(dark, 0) << "lit " << lit;
}

}  // namespace
}  // namespace nave::preprocess
