// Brick decode throughput and size of the brick store, by brick size and Draco speed setting.
// A brick is a tessellated wavy surface with normals, snapped to a grid of 2^14 steps across the
// brick (14-bit-equivalent precision). Counters: triangles/s, decoded MB/s (bytes_per_second is the
// stored size read), bytes per triangle on disk. Results and the command: docs/store-format.md,
// "Measured".

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <tuple>

#include "store/brick_codec.h"
#include "store/store_reader.h"
#include "store/store_writer.h"
#include "store/testing/store_testing.h"

namespace nave::store {
namespace {

struct Fixture {
    BrickMesh mesh;
    GlobalGrid grid;
    EncodedBrick encoded;
};

// `irregular`: jittered vertices and random quad diagonals, closer to a CAD tessellation than the
// grid.
BrickMesh Surface(int64_t triangles, bool irregular) {
    const uint32_t q = uint32_t(std::lround(std::sqrt(double(triangles) / 2.0)));
    testing::SurfaceOptions o;
    o.quads_x = q;
    o.quads_y = q;
    o.size_m = 10.f;
    o.amplitude_m = 0.5f;
    o.uvs = false;
    o.jitter = irregular ? 0.8f : 0.f;
    return testing::MakeSurface(o);
}

// Encoded once per (triangles, speed) and kept for the whole run.
const Fixture& GetFixture(const benchmark::State& state) {
    const int64_t triangles = state.range(0);
    const int speed = int(state.range(1));
    const bool irregular = state.range(2) != 0;
    static std::map<std::tuple<int64_t, int, bool>, std::unique_ptr<Fixture>> cache;
    auto& slot = cache[{triangles, speed, irregular}];
    if (!slot) {
        slot = std::make_unique<Fixture>();
        slot->mesh = Surface(triangles, irregular);
        slot->grid = GlobalGrid{{0, 0, 0}, 10.0 / 16384.0};
        EncodeOptions options;
        options.draco_speed = speed;
        auto encoded = EncodeBrick(slot->mesh, {}, slot->grid, options);
        NAVE_CHECK(encoded.ok()) << encoded.status().ToString();
        slot->encoded = std::move(encoded).value();
    }
    return *slot;
}

void SetCounters(benchmark::State& state, const EncodedBrick& e) {
    const double triangles = double(e.triangle_count);
    state.counters["triangles/s"] =
        benchmark::Counter(triangles, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["decoded_MB/s"] = benchmark::Counter(
        double(e.decoded_bytes) / 1e6, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["bytes/triangle"] = double(e.mesh_bytes.size()) / triangles;
    state.counters["triangles"] = triangles;
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(e.mesh_bytes.size()));
}

// Draco decode of one brick's mesh section into a BrickMesh (what ReadBrick does after the read and
// checksum).
void BM_DecodeBrick(benchmark::State& state) {
    const Fixture& f = GetFixture(state);
    for (auto _ : state) {
        auto mesh = codec::DecodeMeshSection(f.encoded.mesh_bytes, f.grid, 1u << 20, "bench");
        NAVE_CHECK(mesh.ok()) << mesh.status().ToString();
        benchmark::DoNotOptimize(mesh->positions.data());
    }
    SetCounters(state, f.encoded);
}

// Store::ReadBrick from a store file in the page cache: pread + XXH64 + decode + directory checks.
void BM_ReadBrick(benchmark::State& state) {
    const Fixture& f = GetFixture(state);
    const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                       ("nave_bench_store_" + std::to_string(::getpid()) + ".nave");
    {
        auto writer = StoreWriter::Create(path, f.grid, {});
        NAVE_CHECK(writer.ok());
        NAVE_CHECK((*writer)->Append(f.encoded).ok());
        std::vector<BrickTreeNode> leaf(1);
        leaf[0].brick = 0;
        Bounds3f box = f.encoded.geometry_bounds;
        const Status finished =
            (*writer)->Finish(testing::MakeMaterials(3), BrickTree(box, leaf), 0);
        NAVE_CHECK(finished.ok()) << finished.ToString();
    }
    auto store = Store::Open(path);
    NAVE_CHECK(store.ok()) << store.status().ToString();
    for (auto _ : state) {
        auto mesh = (*store)->ReadBrick(0);
        NAVE_CHECK(mesh.ok()) << mesh.status().ToString();
        benchmark::DoNotOptimize(mesh->positions.data());
    }
    SetCounters(state, f.encoded);
    std::filesystem::remove(path);
}

// EncodeBrick (snap, Draco encode, check by decoding once): what preprocess pays per brick.
void BM_EncodeBrick(benchmark::State& state) {
    const Fixture& f = GetFixture(state);
    EncodeOptions options;
    options.draco_speed = int(state.range(1));
    for (auto _ : state) {
        auto e = EncodeBrick(f.mesh, {}, f.grid, options);
        NAVE_CHECK(e.ok());
        benchmark::DoNotOptimize(e->mesh_bytes.data());
    }
    SetCounters(state, f.encoded);
}

void Sizes(benchmark::internal::Benchmark* b) {
    for (int64_t triangles : {10'000, 100'000, 1'000'000}) {
        for (int speed : {0, 3, 5, 6, 7, 8, 10}) b->Args({triangles, speed, 0});
    }
    for (int speed : {0, 3, 5, 6, 7, 8, 10}) b->Args({100'000, speed, 1});
    b->ArgNames({"triangles", "speed", "irregular"})->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_DecodeBrick)->Apply(Sizes);
BENCHMARK(BM_ReadBrick)
    ->Args({100'000, 6, 0})
    ->Args({1'000'000, 6, 0})
    ->Args({100'000, 6, 1})
    ->ArgNames({"triangles", "speed", "irregular"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeBrick)->Apply(Sizes)->Iterations(2);

// What the occupancy grid (format 3.4) adds to EncodeBrick: the same brick with and without it.
void BM_EncodeBrickOccupancy(benchmark::State& state) {
    const Fixture& f = GetFixture(state);
    EncodeOptions options;
    options.draco_speed = int(state.range(1));
    options.occupancy = state.range(3) != 0;
    options.verify = false;  // as preprocess encodes most bricks (verify_every)
    for (auto _ : state) {
        auto e = EncodeBrick(f.mesh, {}, f.grid, options);
        NAVE_CHECK(e.ok());
        benchmark::DoNotOptimize(e->mesh_bytes.data());
    }
    SetCounters(state, f.encoded);
}
BENCHMARK(BM_EncodeBrickOccupancy)
    ->Args({700'000, 6, 1, 0})
    ->Args({700'000, 6, 1, 1})
    ->ArgNames({"triangles", "speed", "irregular", "occupancy"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace
}  // namespace nave::store

// glibc serves large blocks with fresh mmap()s until a free raises its threshold, and page faults
// on fresh memory cost more than Draco's decoding itself on a virtual machine, so timings would
// depend on which benchmark ran first. Unless NAVE_BENCH_DEFAULT_MALLOC is set, keep blocks up to
// 32 MiB on the heap and never trim it: every configuration then decodes into warm memory, as a
// long-running renderer does.
int main(int argc, char** argv) {
    if (std::getenv("NAVE_BENCH_DEFAULT_MALLOC") == nullptr) {
        mallopt(M_MMAP_THRESHOLD, 32 << 20);
        mallopt(M_TRIM_THRESHOLD, 1 << 30);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
