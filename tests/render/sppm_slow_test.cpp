// Photon mapping against path tracing (slow: label "slow"). A glass ball on a floor under the sun
// shows a caustic; SPPM's error against a path-traced reference shrinks as iterations grow.

#include <gtest/gtest.h>

#include "render_test_util.h"
#include "src/core/progress.h"
#include "src/render/bricks/procedural_meshes.h"

namespace nave::render {
namespace {

using testing::MeanY;
using testing::Render;

double RegionMeanY(const Film& f, int x0, int y0, int x1, int y1) {
    double sum = 0;
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x, ++n) sum += f.PixelXYZ(uint32_t(y * f.width() + x)).y;
    return sum / n;
}

TEST(SppmSlow, GlassBallCastsACaustic) {
    ProgressBar::SetEnabled(false);
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {5, 0, 0}, {0, 5, 0}, 8, 0);
    AppendSphere(&m, {0, 0, 0.6f}, 0.5f, 48, 96, 1);
    // Low camera looking under the ball at the floor point below its centre; sun at the zenith.
    const char* config = R"(
[camera]
position = [3, 0, 0.25]
look_at = [0, 0, 0]
fov_deg = 20
resolution = [48, 32]
[sun]
direction = [0, 0, 1]
radiance = 1000.0
[materials.floor]
reflectance = 0.5
[materials.glass]
type = "dielectric"
eta = 1.5
[render]
mode = "photon"
iterations = 8
photons_per_iteration = 200000
initial_radius_m = 0.02
seed = 5
)";
    auto t = Render(m, {"floor", "glass"}, config, 2);
    ASSERT_TRUE(t);
    // The floor under the ball (image centre) is in the ball's shadow for direct sunlight, yet the
    // ball focuses the sunlight that crosses it there: its brightest pixel outshines the directly
    // lit floor.
    auto region_max = [](const Film& f) {
        double best = 0;
        for (int y = 15; y < 18; ++y)
            for (int x = 20; x < 28; ++x)
                best = std::max(best, f.PixelXYZ(uint32_t(y * f.width() + x)).y);
        return best;
    };
    double caustic = region_max(*t->film);
    double lit_floor = RegionMeanY(*t->film, 0, 26, 6, 32);
    EXPECT_GT(caustic, 2 * lit_floor) << "caustic " << caustic << " lit floor " << lit_floor;
}

double Rmse(const Film& a, const Film& b) {
    double s = 0;
    for (size_t p = 0; p < a.pixel_count(); ++p) {
        double d = a.PixelXYZ(uint32_t(p)).y - b.PixelXYZ(uint32_t(p)).y;
        s += d * d;
    }
    return std::sqrt(s / double(a.pixel_count()));
}

TEST(SppmSlow, ConvergesTowardPathTracedReference) {
    ProgressBar::SetEnabled(false);
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 6, 0);
    AppendSphere(&m, {0.5f, 0.3f, 1.0f}, 0.8f, 16, 32, 1);
    AppendBox(&m, Bounds3f({1.0f, -2.5f, 0.01f}, {2.5f, -1.2f, 1.8f}), 0);
    const char* base = R"(
[camera]
position = [6, 5, 3.5]
look_at = [0, 0, 0.6]
fov_deg = 45
resolution = [24, 18]
[sun]
direction = [0.4, -0.5, 0.75]
radiance = 1000.0
[materials.floor]
reflectance = 0.7
[materials.ball]
reflectance = 0.5
[render]
mode = "{}"
spp = {}
iterations = {}
photons_per_iteration = 100000
max_depth = 16
seed = 9
)";
    auto reference =
        Render(m, {"floor", "ball"}, fmt::format(fmt::runtime(base), "path", 1024, 1), 1);
    auto few = Render(m, {"floor", "ball"}, fmt::format(fmt::runtime(base), "photon", 1, 2), 2);
    auto many = Render(m, {"floor", "ball"}, fmt::format(fmt::runtime(base), "photon", 1, 32), 2);
    ASSERT_TRUE(reference && few && many);
    double e_few = Rmse(*few->film, *reference->film), e_many = Rmse(*many->film, *reference->film);
    double mean = MeanY(*reference->film);
    EXPECT_LT(e_many, 0.7 * e_few) << "rmse 2 iterations " << e_few << ", 32 iterations " << e_many;
    EXPECT_LT(e_many, 0.15 * mean) << "rmse " << e_many << " vs mean " << mean;
    EXPECT_NEAR(MeanY(*many->film), mean, 0.03 * mean);
}

// Indirect light through a window: photons aimed at the portals only must give the same image as
// photons aimed at the model's bounds (the portal estimator is unbiased, also where two portals
// overlap as seen from the sun: here a second pane hangs below the roof window).
TEST(SppmSlow, PortalPhotonsMatchBoundsPhotons) {
    ProgressBar::SetEnabled(false);
    store::BrickMesh m = testing::RoomWithRoofWindow();
    AppendQuad(&m, {0.4f, 0.3f, 1.8f}, {0.5f, 0, 0}, {0, 0.5f, 0}, 1,
               2);  // a pane under the window
    constexpr const char* kRoom = R"(
[camera]
position = [1.8, 1.8, 2.5]
look_at = [0, 0, 0]
fov_deg = 70
resolution = [12, 12]
{}
[materials.floor]
reflectance = 0.6
[materials.wall]
reflectance = 0.6
[materials.window]
type = "thin_dielectric"
eta = 1.5
transmittance = 0.9
portal = true
[materials.reflector]
reflectance = 0.9
[render]
mode = "photon"
iterations = 8
photons_per_iteration = {}
photon_target = "{}"
initial_radius_m = 0.1
max_depth = 6
seed = 4
)";
    std::vector<std::string> names = {"floor", "wall", "window", "reflector"};
    // Light reflected into the window from outside: a bright wall standing on the roof beside the
    // window, facing a low sun. No line through the window carries it from the light, so portal
    // photons alone miss it; photons aimed at the bounds too find it.
    store::BrickMesh with_reflector = m;
    AppendQuad(&with_reflector, {-1.2f, 0, 4.5f}, {0, 1.5f, 0}, {0, 0, 1.5f}, 2, 3);
    struct Case {
        const store::BrickMesh* mesh;
        const char* light;
    };
    // The sun (portal projections) and a uniform sky (portal-area lines counted with Embree).
    for (const Case& c :
         {Case{&m, "[sun]\ndirection = [0.1, 0.05, 1]\nradiance = 1000.0"},
          Case{&m, "[sky]\nradiance = 1.0"},
          Case{&with_reflector, "[sun]\ndirection = [1, 0, 0.6]\nradiance = 1000.0"},
          Case{&with_reflector, "[sky]\nradiance = 1.0"}}) {
        auto bounds =
            Render(*c.mesh, names, fmt::format(fmt::runtime(kRoom), c.light, 400000, "bounds"), 2);
        auto portals =
            Render(*c.mesh, names, fmt::format(fmt::runtime(kRoom), c.light, 100000, "portals"), 2);
        ASSERT_TRUE(bounds && portals);
        double b = MeanY(*bounds->film), p = MeanY(*portals->film);
        EXPECT_GT(b, 0);
        EXPECT_NEAR(p, b, 0.03 * b) << c.light << (c.mesh == &m ? "" : ", with the reflector")
                                    << ": bounds " << b << " portals " << p;
    }
}

}  // namespace
}  // namespace nave::render
