// How the config's [materials] tables reach the model's materials: a name's own table first, else
// the longest glob pattern that matches it ("*glazing*" for every pane of an IFC building), else
// "default"; and `reflectance = "model"`, which takes the model material's own colour.

#include <gtest/gtest.h>

#include <variant>

#include "render_test_util.h"
#include "src/core/color.h"

namespace nave::render {
namespace {

// One triangle per material, so that every material is in the model.
store::BrickMesh TrianglePerMaterial(uint32_t materials) {
    store::BrickMesh m;
    for (uint32_t i = 0; i < materials; ++i) {
        const float x = float(i);
        const uint32_t base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), {{x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
        m.material_ids.push_back(i);
    }
    return m;
}

constexpr const char* kCamera = "[camera]\nposition = [0, -5, 1]\nlook_at = [0, 0, 0]\n";

StatusOr<std::unique_ptr<testing::TestScene>> Build(std::vector<store::MaterialRecord> records,
                                                    const std::string& materials_toml) {
    const uint32_t n = uint32_t(records.size());
    NAVE_ASSIGN_OR_RETURN(SceneConfig config,
                          ParseSceneConfig(std::string(kCamera) + materials_toml, "map.toml"));
    return testing::BuildTestScene(
        testing::GridSource(TrianglePerMaterial(n), std::move(records), Vec3i(1, 1, 1)),
        std::move(config));
}

TEST(MaterialMapping, NamesThenTheLongestMatchingPatternThenTheDefault) {
    auto scene = Build(testing::NamedMaterials({"IfcWall:Limestone", "IfcWindow glazing:Glass",
                                                "IfcWindow:Oak", "IfcPlate glazing", "Altar"}),
                       "[materials.\"*glazing*\"]\nbuiltin = \"window_glass\"\nportal = true\n"
                       "[materials.\"IfcWindow*\"]\ntype = \"black\"\n"
                       "[materials.\"IfcWindow glazing*\"]\ntype = \"thin_dielectric\"\n"
                       "[materials.Altar]\ntype = \"conductor\"\n"
                       "[materials.default]\nreflectance = 0.25\n");
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    const auto& m = (*scene)->scene.materials;
    ASSERT_EQ(m.size(), 5u);
    EXPECT_TRUE(std::holds_alternative<DiffuseMaterial>(m[0].material));  // default
    EXPECT_FLOAT_EQ(std::get<DiffuseMaterial>(m[0].material).albedo.Evaluate(550), 0.25f);
    // "IfcWindow glazing*" is longer than "*glazing*" and "IfcWindow*": the most specific.
    EXPECT_TRUE(std::holds_alternative<ThinGlassMaterial>(m[1].material));
    EXPECT_FALSE(m[1].portal);
    EXPECT_TRUE(m[2].black);                                                // "IfcWindow*"
    EXPECT_TRUE(std::holds_alternative<ThinGlassMaterial>(m[3].material));  // "*glazing*"
    EXPECT_TRUE(m[3].portal);
    EXPECT_TRUE(std::holds_alternative<ConductorMaterial>(m[4].material));  // its own name
}

TEST(MaterialMapping, APatternMatchingNothingIsAWarningNotAnError) {
    auto scene = Build(testing::NamedMaterials({"Altar"}),
                       "[materials.\"Ifc*\"]\ntype = \"black\"\n[materials.default]\n");
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    EXPECT_FALSE((*scene)->scene.materials[0].black);
}

TEST(MaterialMapping, ReflectanceFromTheModelsColour) {
    std::vector<store::MaterialRecord> records = testing::NamedMaterials({"red", "grey"});
    records[0].diffuse = {0.8f, 0.1f, 0.1f};
    records[1].diffuse = {0.5f, 0.5f, 0.5f};
    auto scene = Build(records, "[materials.default]\nreflectance = \"model\"\n");
    ASSERT_TRUE(scene.ok()) << scene.status().ToString();
    const auto& red = std::get<DiffuseMaterial>((*scene)->scene.materials[0].material).albedo;
    const auto& grey = std::get<DiffuseMaterial>((*scene)->scene.materials[1].material).albedo;
    // Red reflects long wavelengths and not short ones; grey is flat at its value.
    EXPECT_GT(red.Evaluate(650), 0.6f);
    EXPECT_LT(red.Evaluate(450), 0.2f);
    EXPECT_NEAR(grey.Evaluate(450), 0.5f, 0.02f);
    EXPECT_NEAR(grey.Evaluate(650), 0.5f, 0.02f);

    auto bad = Build(records, "[materials.default]\nreflectance = \"paint\"\n");
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.status().message().find("\"model\""), std::string::npos)
        << bad.status().message();
}

}  // namespace
}  // namespace nave::render
