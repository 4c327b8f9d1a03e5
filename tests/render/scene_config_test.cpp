// Scene configs: every key parsed, and bad keys, types and dates rejected with file, line and key.

#include "src/render/scene/scene_config.h"

#include <gtest/gtest.h>

namespace nave::render {
namespace {

constexpr const char* kGood = R"(
[camera]
position = [1, 2, 3]
look_at = [4, 2, 3]
fov_deg = 45
resolution = [320, 200]

[sun]
datetime = "2025-06-21T08:00+02:00"
latitude_deg = 49.14
longitude_deg = 2.38
turbidity = 2.5

[sky]
type = "uniform"
radiance = { value = 0.2 }

[[lights]]
type = "point"
position = [0, 0, 5]
intensity = { blackbody_k = 3000, scale = 10 }

[materials.limestone]
reflectance = { wavelengths_nm = [400, 700], values = [0.5, 0.7] }

[materials.glass_clear]
type = "dielectric"
eta = 1.52
portal = true

[render]
mode = "photon"
iterations = 8
seed = 42
photon_target = "portals"

[output]
aovs = ["albedo", "depth"]
white_balance = "D65"
)";

TEST(SceneConfig, ParsesEveryPart) {
    auto c = ParseSceneConfig(kGood, "good.toml");
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    EXPECT_EQ(c->camera.width, 320);
    EXPECT_FLOAT_EQ(c->camera.fov_deg, 45);
    EXPECT_TRUE(c->sun.enabled);
    EXPECT_EQ(c->sun.when.hour, 8);
    EXPECT_EQ(c->sun.when.utc_offset_minutes, 120);
    EXPECT_DOUBLE_EQ(c->sun.latitude_deg, 49.14);
    EXPECT_EQ(c->sky.kind, SkyConfig::Kind::kUniform);
    ASSERT_EQ(c->lights.size(), 1u);
    EXPECT_EQ(c->lights[0].kind, LightConfig::Kind::kPoint);
    EXPECT_NEAR(c->materials.at("limestone").reflectance.Evaluate(550), 0.6f, 1e-6);
    EXPECT_EQ(c->materials.at("glass_clear").kind, MaterialConfig::Kind::kDielectric);
    EXPECT_TRUE(c->materials.at("glass_clear").portal);
    EXPECT_EQ(c->render.mode, RenderSettings::Mode::kPhoton);
    EXPECT_EQ(c->render.seed, 42u);
    EXPECT_EQ(c->render.photon_target, RenderSettings::PhotonTarget::kPortals);
    EXPECT_TRUE(c->output.aov_albedo && c->output.aov_depth && !c->output.aov_normal);
}

TEST(SceneConfig, UnknownKeyNamesKeyFileAndLine) {
    auto c = ParseSceneConfig("[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\nfovv = 40\n",
                              "scene.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("scene.toml:4:1"), std::string::npos)
        << c.status().message();
    EXPECT_NE(c.status().message().find("camera.fovv"), std::string::npos) << c.status().message();
}

TEST(SceneConfig, UnknownKeyInsideNestedTable) {
    auto c = ParseSceneConfig(
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[materials.wood]\nreflectance = {value = "
        "0.3, scael = 2}\n",
        "s.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("materials.wood.reflectance.scael"), std::string::npos)
        << c.status().message();
}

TEST(SceneConfig, UnknownTopLevelTable) {
    auto c = ParseSceneConfig("[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[rendr]\nspp = 4\n",
                              "s.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("'rendr'"), std::string::npos) << c.status().message();
}

// A photon's number within its iteration keys its random numbers in 32 bits: more photons than that
// in one iteration would repeat each other's, so the config refuses them.
TEST(SceneConfig, PhotonsPerIterationFitIn32Bits) {
    const std::string camera = "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[render]\n";
    auto most = ParseSceneConfig(camera + "photons_per_iteration = 4294967295\n", "s.toml");
    ASSERT_TRUE(most.ok()) << most.status().ToString();
    EXPECT_EQ(most->render.photons_per_iteration, 4294967295);
    auto over = ParseSceneConfig(camera + "photons_per_iteration = 4294967296\n", "s.toml");
    ASSERT_FALSE(over.ok());
    EXPECT_NE(over.status().message().find("render.photons_per_iteration"), std::string::npos)
        << over.status().message();
}

// A store's levels of detail are used unless the config says "full"; a bad value names the key.
TEST(SceneConfig, LevelsOfDetailAreUsedUnlessFullIsAsked) {
    const std::string camera = "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[render]\n";
    auto plain = ParseSceneConfig(camera, "s.toml");
    ASSERT_TRUE(plain.ok()) << plain.status().ToString();
    EXPECT_EQ(plain->render.lod, RenderSettings::Lod::kAuto);
    auto full = ParseSceneConfig(camera + "lod = \"full\"\n", "s.toml");
    ASSERT_TRUE(full.ok()) << full.status().ToString();
    EXPECT_EQ(full->render.lod, RenderSettings::Lod::kFull);
    auto bad = ParseSceneConfig(camera + "lod = \"coarse\"\n", "s.toml");
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.status().message().find("render.lod"), std::string::npos)
        << bad.status().message();
}

TEST(SceneConfig, FinalGatherAndTheSkysDirectLightFromPhotonsExcludeEachOther) {
    auto c = ParseSceneConfig(
        "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[render]\nmode = \"photon\"\n"
        "final_gather = true\nsky_direct = \"photons\"\n",
        "gather.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("gather.toml"), std::string::npos) << c.status().ToString();
    EXPECT_NE(c.status().message().find("render.final_gather"), std::string::npos)
        << c.status().ToString();
    EXPECT_NE(c.status().message().find("render.sky_direct"), std::string::npos)
        << c.status().ToString();
    auto ok = ParseSceneConfig(
        "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[render]\nmode = \"photon\"\n"
        "final_gather = true\n",
        "gather.toml");
    ASSERT_TRUE(ok.ok()) << ok.status().ToString();
    EXPECT_TRUE(ok->render.final_gather);
}

TEST(SceneConfig, WrongTypeSaysExpectedAndFound) {
    auto c = ParseSceneConfig(
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\nfov_deg = \"wide\"\n", "s.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("s.toml:4"), std::string::npos) << c.status().message();
    EXPECT_NE(c.status().message().find("expected a number, found string"), std::string::npos)
        << c.status().message();
}

TEST(SceneConfig, BadDates) {
    const char* base =
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[sun]\ndatetime = \"{}\"\n";
    for (const char* bad : {"2025-02-30T08:00+01:00", "2025-13-01T08:00Z", "2025-06-21T25:00Z",
                            "2025-06-21T08:00", "21/06/2025 08:00"}) {
        auto c = ParseSceneConfig(fmt::format(fmt::runtime(base), bad), "sun.toml");
        ASSERT_FALSE(c.ok()) << bad;
        EXPECT_NE(c.status().message().find("sun.toml:5"), std::string::npos)
            << c.status().message();
        EXPECT_NE(c.status().message().find("sun.datetime"), std::string::npos)
            << c.status().message();
    }
    auto leap = ParseDateTime("2024-02-29T12:00:30.5-05:30");
    ASSERT_TRUE(leap.ok()) << leap.status().ToString();
    EXPECT_EQ(leap->utc_offset_minutes, -330);
    EXPECT_DOUBLE_EQ(leap->second, 30.5);
    // Native TOML date-times are accepted too.
    auto native = ParseSceneConfig(
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[sun]\n"
        "datetime = 2025-06-21T08:00:00+02:00\nlatitude_deg = 49\n",
        "n.toml");
    ASSERT_TRUE(native.ok()) << native.status().ToString();
    EXPECT_EQ(native->sun.when.utc_offset_minutes, 120);
}

TEST(SceneConfig, SyntaxErrorHasLocation) {
    auto c = ParseSceneConfig("[camera\nposition = [0,0,0]\n", "broken.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("broken.toml:1"), std::string::npos)
        << c.status().message();
}

TEST(SceneConfig, MissingCameraAndBadMode) {
    EXPECT_FALSE(ParseSceneConfig("", "e.toml").ok());
    auto c = ParseSceneConfig(
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[render]\nmode = \"bidir\"\n", "m.toml");
    ASSERT_FALSE(c.ok());
    EXPECT_NE(c.status().message().find("bidir"), std::string::npos);
}

TEST(SceneConfig, SpectrumFromCsvColumnOfNavesData) {
    auto c = ParseSceneConfig(
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[materials.glass_blue]\n"
        "type = \"thin_dielectric\"\ntransmittance = { csv = \"stained_glass_approx.csv\", "
        "column = \"glass_blue\" }\n",
        "g.toml");
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    const SpectrumSpec& t = c->materials.at("glass_blue").transmittance;
    EXPECT_EQ(t.kind, SpectrumSpec::Kind::kTable);
    EXPECT_GT(t.Evaluate(450), 2 * t.Evaluate(620));  // blue glass passes blue, not red
    auto bad = ParseSceneConfig(
        "[camera]\nposition = [0,0,0]\nlook_at = [1,0,0]\n[materials.x]\n"
        "reflectance = { csv = \"stone_approx.csv\", column = \"marble\" }\n",
        "g.toml");
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.status().message().find("limestone"), std::string::npos)
        << bad.status().message();
}

TEST(SpectrumSpec, BlackbodyPeaksAtWien) {
    SpectrumSpec s;
    s.kind = SpectrumSpec::Kind::kBlackbody;
    s.temperature_k = 5000;
    // Wien's displacement law: lambda_max = 2.897771955e-3 m K / T = 579.55 nm at 5000 K.
    EXPECT_NEAR(s.Evaluate(579.55f), 1.0f, 1e-4);
    EXPECT_LT(s.Evaluate(450), 1.0f);
    EXPECT_LT(s.Evaluate(700), 1.0f);
}

}  // namespace
}  // namespace nave::render
