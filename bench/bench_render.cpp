// Ray streams over bricks: rays per second for the same scene cut into 1, 8 and 64 bricks, all
// resident (the cost of the decomposition itself: queueing, moving rays between bricks, per-brick
// Embree scenes), and photons per second of the SPPM photon pass.
//   build/release/bench/bench_render --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <limits>
#include <random>

#include "src/core/progress.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/bricks/grid_bricks.h"
#include "src/render/bricks/memory_brick_source.h"
#include "src/render/bricks/procedural_meshes.h"
#include "src/render/film/film.h"
#include "src/render/integrators/render_streams.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/scene_config.h"
#include "src/render/stream/ray_message.h"

namespace nave::render {
namespace {

/// About 1.1 M triangles: a tessellated floor, a grid of 16 spheres, boxes; lit by sun and sky.
store::BrickMesh BenchMesh() {
    store::BrickMesh m;
    AppendQuad(&m, {0, 0, 0}, {8, 0, 0}, {0, 8, 0}, 200, 0);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            AppendSphere(&m, {-6 + 4.f * i, -6 + 4.f * j, 1.2f}, 1.0f, 96, 192,
                         uint32_t((i + j) % 2 + 1));
    for (int i = 0; i < 5; ++i)
        AppendBox(&m, Bounds3f({-7.5f + 3 * i, 6.5f, 0}, {-6.5f + 3 * i, 7.5f, 4.f}), 0);
    return m;
}

constexpr const char* kConfig = R"(
[camera]
position = [10, -12, 7]
look_at = [0, 0, 0.5]
fov_deg = 50
resolution = [256, 192]
[sun]
direction = [0.3, -0.4, 0.85]
radiance = 10000.0
[sky]
radiance = 0.5
[materials.floor]
reflectance = 0.6
[materials.ball]
reflectance = 0.4
[materials.chrome]
type = "conductor"
roughness = 0.3
[render]
mode = "{}"
spp = 4
iterations = 1
photons_per_iteration = 1000000
max_depth = 6
)";

struct Fixture {
    std::unique_ptr<MemoryBrickSource> source;
    SceneConfig config;
    RenderScene scene;
};

/// Haze over the scene's bounds for BM_PathRaysInMedium: an optical depth of about 1 across the
/// model, forward scattering.
constexpr const char* kMedium = R"(
[medium]
sigma_s = 0.08
sigma_a = 0.005
g = 0.6
)";

/// The same haze glowing (emission: gathered along every flight, EmissionAlong) for
/// BM_PathRaysInGlowingMedium.
constexpr const char* kGlowingMedium = R"(
[medium]
sigma_s = 0.08
sigma_a = 0.005
g = 0.6
emission = 20
)";

std::unique_ptr<Fixture> MakeFixture(int split, const char* mode, const char* extra = "") {
    static const store::BrickMesh mesh = BenchMesh();
    auto f = std::make_unique<Fixture>();
    auto device = EmbreeDevice::Create();
    GridBricks grid = SplitIntoGridBricks(mesh, split, split, split);
    std::vector<store::MaterialRecord> materials(3);
    materials[0].name = "floor";
    materials[1].name = "ball";
    materials[2].name = "chrome";
    f->source = std::make_unique<MemoryBrickSource>(*device, grid.tree, grid.meshes, materials);
    f->config =
        ParseSceneConfig(fmt::format(fmt::runtime(kConfig), mode) + extra, "bench.toml").value();
    f->scene = BuildRenderScene(f->config, *f->source).value();
    for (uint32_t b = 0; b < f->source->brick_count(); ++b)
        (void)f->source->Acquire(b);  // all resident
    return f;
}

/// Path rays through `f`: rays/s, and the rays and time per camera path (which a medium's
/// scatterings lengthen).
void RunPathRays(benchmark::State& state, Fixture* f) {
    uint64_t rays = 0, brick_moves = 0, segments = 0, paths = 0;
    for (auto _ : state) {
        Film film(f->config.camera.width, f->config.camera.height, f->config.output);
        RenderStats stats;
        if (!RenderStreams(f->scene, &film, &stats).ok()) state.SkipWithError("render failed");
        rays += stats.rays;
        segments += stats.segments_traced + stats.shadow_segments;
        brick_moves += stats.brick_moves;
        paths += stats.camera_paths;
    }
    state.counters["bricks"] = double(f->source->brick_count());
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
    state.counters["paths/s"] = benchmark::Counter(double(paths), benchmark::Counter::kIsRate);
    state.counters["rays/path"] = double(rays) / double(std::max<uint64_t>(1, paths));
    state.counters["brick_moves/ray"] = double(brick_moves) / double(std::max<uint64_t>(1, rays));
    state.counters["segments/ray"] = double(segments) / double(std::max<uint64_t>(1, rays));
}

void BM_PathRays(benchmark::State& state) {
    ProgressBar::SetEnabled(false);
    auto f = MakeFixture(int(state.range(0)), "path");
    RunPathRays(state, f.get());
}
BENCHMARK(BM_PathRays)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

/// The same scene in haze ([medium]): the cost of the medium per path and per ray.
void BM_PathRaysInMedium(benchmark::State& state) {
    ProgressBar::SetEnabled(false);
    auto f = MakeFixture(int(state.range(0)), "path", kMedium);
    RunPathRays(state, f.get());
}
BENCHMARK(BM_PathRaysInMedium)
    ->Arg(1)
    ->Arg(4)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

/// The haze glowing: the cost of gathering its emission along every flight.
void BM_PathRaysInGlowingMedium(benchmark::State& state) {
    ProgressBar::SetEnabled(false);
    auto f = MakeFixture(int(state.range(0)), "path", kGlowingMedium);
    RunPathRays(state, f.get());
}
BENCHMARK(BM_PathRaysInGlowingMedium)
    ->Arg(1)
    ->Arg(4)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

void BM_Photons(benchmark::State& state) {
    ProgressBar::SetEnabled(false);
    auto f = MakeFixture(int(state.range(0)), "photon");
    uint64_t photons = 0;
    for (auto _ : state) {
        Film film(f->config.camera.width, f->config.camera.height, f->config.output);
        RenderStats stats;
        if (!RenderStreams(f->scene, &film, &stats).ok()) state.SkipWithError("render failed");
        photons += stats.photons;
    }
    state.counters["bricks"] = double(f->source->brick_count());
    state.counters["photons/s"] = benchmark::Counter(double(photons), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Photons)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

/// Packing a message of rays for the wire (PackRayMessage) and unpacking it: raw bytes/s each way
/// and the packed size. The rays are a brick's batch at its worst for LZ4: origins anywhere in a
/// 10 m box, directions, wavelengths and throughputs at random, pixels anywhere in a 960x640 image
/// (real batches, whose rays share origins and pixels, pack smaller: docs/distributed.md).
void BM_PackRayMessage(benchmark::State& state) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<RayRecord> rays(8000);
    for (RayRecord& r : rays) {
        r.origin = Vec3f(10 * u(rng), 10 * u(rng), 10 * u(rng));
        r.dir = Normalize(Vec3f(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
        r.t_max = std::numeric_limits<float>::infinity();
        r.t_enter = u(rng);
        r.t_exit = r.t_enter + 3 * u(rng);
        r.pixel = uint32_t(u(rng) * 960 * 640);
        r.sample = uint32_t(u(rng) * 4);
        r.depth = uint8_t(1 + u(rng) * 4);
        r.vertex = r.depth;
        r.prev_pdf = u(rng);
        r.cone_width = 0.01f * u(rng);
        r.cone_spread = 0.002f;
        r.lambda = SampledWavelengths::SampleVisible(u(rng));
        for (int i = 0; i < kNumWavelengths; ++i) r.beta[i] = u(rng);
    }
    RayMessage message;
    message.Append(3, rays);
    const std::vector<std::byte> raw = message.Take();
    size_t packed_bytes = 0;
    std::vector<std::byte> unpacked;
    for (auto _ : state) {
        const std::vector<std::byte> packed = PackRayMessage(raw);
        packed_bytes = packed.size();
        if (!UnpackRayMessage(packed, raw.size(), "bench", &unpacked).ok())
            state.SkipWithError("unpack failed");
    }
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(raw.size()));
    state.counters["bytes/ray packed"] = double(packed_bytes) / double(rays.size());
}
BENCHMARK(BM_PackRayMessage)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace nave::render

BENCHMARK_MAIN();
