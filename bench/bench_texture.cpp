// Texture lookups: filtered lookups per second through TextureCache with a warm cache (all tiles
// resident), a cold one (every run starts from an empty cache, tiles read and decompressed from
// the file) and a cache smaller than the data (random lookups over 4 textures of 16 MiB each
// through the 10 MiB minimum: tiles are evicted and re-read); RGB -> spectrum uplift lookups and
// the time to solve the sRGB table.
//   build/release/bench/bench_texture --benchmark_counters_tabular=true

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "src/core/rgb_to_spectrum.h"
#include "src/imaging/texture_cache.h"

namespace nave::render {
namespace {

using namespace nave::imaging;

constexpr int kSize = 2048;

// Tiled, MIP-mapped RGBA half textures of kSize² with a smooth pattern, made once per process.
const std::vector<std::filesystem::path>& BenchTextures() {
    static std::vector<std::filesystem::path> paths = [] {
        std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("nave_bench_texture_" + std::to_string(getpid()));
        std::filesystem::create_directories(dir);
        std::vector<std::filesystem::path> out;
        for (int k = 0; k < 4; ++k) {
            OIIO::ImageBuf buf(OIIO::ImageSpec(kSize, kSize, 4, OIIO::TypeFloat));
            std::vector<float> row(size_t(kSize) * 4);
            for (int y = 0; y < kSize; ++y) {
                for (int x = 0; x < kSize; ++x) {
                    row[x * 4 + 0] = 0.5f + 0.5f * std::sin(0.01f * float(x + k * 37));
                    row[x * 4 + 1] = 0.5f + 0.5f * std::cos(0.013f * float(y));
                    row[x * 4 + 2] = float((x ^ y) & 255) / 255.f;
                    row[x * 4 + 3] = 1.f;
                }
                buf.set_pixels(OIIO::ROI(0, kSize, y, y + 1), OIIO::TypeFloat, row.data());
            }
            OIIO::ImageSpec config;
            config.format = OIIO::TypeHalf;
            config.tile_width = config.tile_height = 64;
            out.push_back(dir / ("bench" + std::to_string(k) + ".tx"));
            if (!OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, buf,
                                                  out.back().string(), config))
                std::abort();
        }
        std::atexit([] {
            std::filesystem::remove_all(std::filesystem::temp_directory_path() /
                                        ("nave_bench_texture_" + std::to_string(getpid())));
        });
        return out;
    }();
    return paths;
}

// Random coordinates with a footprint of about one texel of the finest level.
void RunLookups(benchmark::State& state, TextureCache& cache, const std::vector<TextureRef>& refs,
                int count, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    TextureFootprint fp = TextureFootprint::Isotropic(1.f / kSize);
    float rgba[4];
    for (int i = 0; i < count; ++i) {
        TextureRef r = refs[size_t(i) % refs.size()];
        if (!cache.Lookup(r, u(rng), u(rng), fp, 0, 4, rgba).ok()) {
            state.SkipWithError("lookup failed");
            return;
        }
        benchmark::DoNotOptimize(rgba[0]);
    }
}

void BM_TextureLookupWarm(benchmark::State& state) {
    auto cache = TextureCache::Create(size_t(256) << 20).value();
    std::vector<TextureRef> refs = {cache->Open(BenchTextures()[0]).value()};
    std::mt19937 rng(1);
    RunLookups(state, *cache, refs, 200000, rng);  // warm every tile
    for (auto _ : state) RunLookups(state, *cache, refs, 10000, rng);
    state.SetItemsProcessed(state.iterations() * 10000);
    state.counters["cache_MiB"] = double(cache->memory_used_bytes()) / (1 << 20);
}
BENCHMARK(BM_TextureLookupWarm)->Unit(benchmark::kMillisecond);

void BM_TextureLookupCold(benchmark::State& state) {
    std::mt19937 rng(2);
    uint64_t read = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto cache = TextureCache::Create(size_t(256) << 20).value();
        std::vector<TextureRef> refs = {cache->Open(BenchTextures()[0]).value()};
        state.ResumeTiming();
        RunLookups(state, *cache, refs, 10000, rng);
        read += cache->bytes_read();
    }
    state.SetItemsProcessed(state.iterations() * 10000);
    state.counters["MiB_read_per_run"] = double(read) / double(state.iterations()) / (1 << 20);
}
BENCHMARK(BM_TextureLookupCold)->Unit(benchmark::kMillisecond);

void BM_TextureLookupOverCap(benchmark::State& state) {
    auto cache = TextureCache::Create(size_t(10) << 20).value();
    std::vector<TextureRef> refs;
    for (const auto& p : BenchTextures()) refs.push_back(cache->Open(p).value());
    std::mt19937 rng(3);
    for (auto _ : state) RunLookups(state, *cache, refs, 10000, rng);
    state.SetItemsProcessed(state.iterations() * 10000);
    state.counters["cache_MiB"] = double(cache->memory_used_bytes()) / (1 << 20);
    state.counters["MiB_read"] = double(cache->bytes_read()) / (1 << 20);
}
BENCHMARK(BM_TextureLookupOverCap)->Unit(benchmark::kMillisecond);

void BM_UpliftTableSolve(benchmark::State& state) {
    for (auto _ : state) {
        RgbToSpectrumTable table(RgbColorSpace::Srgb());
        benchmark::DoNotOptimize(table.max_node_delta_e());
    }
}
BENCHMARK(BM_UpliftTableSolve)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_UpliftLookup(benchmark::State& state) {
    const RgbToSpectrumTable& table = RgbToSpectrumTable::For(RgbColorSpace::Srgb());
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<Vec3f> colours;
    colours.reserve(4096);
    for (int i = 0; i < 4096; ++i) colours.emplace_back(u(rng), u(rng), u(rng));
    SampledWavelengths lambda = SampledWavelengths::SampleVisible(0.3f);
    size_t i = 0;
    for (auto _ : state) {
        SampledSpectrum s = table.Lookup(colours[i++ & 4095]).Sample(lambda);
        benchmark::DoNotOptimize(s);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_UpliftLookup);

}  // namespace
}  // namespace nave::render

BENCHMARK_MAIN();
