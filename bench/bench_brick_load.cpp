// What one brick load costs, stage by stage, on real bricks of a store, next to the raw rates of
// the libraries on the same data: read (pread from the page cache), checksum (XXH64), Draco's own
// decode, nave's decode into a BrickMesh (Draco plus the copy into flat arrays), Embree's BVH build
// at each quality with and without compact nodes, on one thread and on all, and the whole load as
// the renderer makes it (Store::ReadBrick + ResidentBrick::Build). Counters: triangles/s (per load,
// wall time) and the resident bytes per triangle of each build.
//
//     NAVE_BENCH_STORE=/tmp/nave-scale/abbey110.nave build/release/bench/bench_brick_load
//
// Bricks: the smallest, the median and the largest of the store by triangle count (brick ids in the
// benchmark names). Without NAVE_BENCH_STORE the benchmarks are skipped with a message. Results and
// their reading: docs/pager.md, "Brick loads".

#include <benchmark/benchmark.h>
#include <draco/compression/decode.h>
#include <embree3/rtcore.h>
#include <malloc.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "src/core/file.h"
#include "src/core/hash.h"
#include "src/render/bricks/brick_source.h"
#include "store/brick_codec.h"  // internal to nave_store: the mesh section decoder
#include "store/store_reader.h"

namespace nave {
namespace {

// Embree's own count of the bytes it holds (its memory monitor callback): the BVH's resident size
// and its build's peak, per triangle.
std::atomic<int64_t> g_embree_bytes{0};
std::atomic<int64_t> g_embree_peak{0};
bool CountEmbreeBytes(void*, ssize_t bytes, bool) {
    const int64_t now = g_embree_bytes.fetch_add(bytes) + bytes;
    int64_t peak = g_embree_peak.load();
    while (now > peak && !g_embree_peak.compare_exchange_weak(peak, now)) {
    }
    return true;
}

struct Data {
    std::unique_ptr<store::Store> store;
    std::unique_ptr<ReadOnlyFile> file;
    std::shared_ptr<render::EmbreeDevice> device;
    std::vector<uint32_t> bricks;  // smallest, median, largest
};

const Data* GetData() {
    static const Data* data = []() -> const Data* {
        const char* path = std::getenv("NAVE_BENCH_STORE");
        if (path == nullptr) return nullptr;
        auto d = new Data;
        auto st = store::Store::Open(path);
        NAVE_CHECK(st.ok()) << st.status().ToString();
        d->store = std::move(st).value();
        auto f = ReadOnlyFile::Open(path);
        NAVE_CHECK(f.ok()) << f.status().ToString();
        d->file = std::make_unique<ReadOnlyFile>(std::move(f).value());
        auto dev = render::EmbreeDevice::Create();
        NAVE_CHECK(dev.ok()) << dev.status().ToString();
        d->device = std::move(dev).value();
        rtcSetDeviceMemoryMonitorFunction(static_cast<RTCDevice>(d->device->handle()),
                                          CountEmbreeBytes, nullptr);
        std::vector<uint32_t> order(d->store->bricks().size());
        for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
        const auto& b = d->store->bricks();
        std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
            return b[x].triangle_count < b[y].triangle_count;
        });
        d->bricks = {order.front(), order[order.size() / 2], order.back()};
        return d;
    }();
    return data;
}

/// The brick of size class state.range(0) (0 smallest, 1 median, 2 largest), or skips the
/// benchmark.
const store::BrickInfo* Brick(benchmark::State& state, const Data** data) {
    *data = GetData();
    if (*data == nullptr) {
        state.SkipWithError("set NAVE_BENCH_STORE to a .nave store (e.g. the detail-110 abbey)");
        return nullptr;
    }
    return &(*data)->store->bricks()[(*data)->bricks[size_t(state.range(0))]];
}

void SetRate(benchmark::State& state, const store::BrickInfo& b) {
    state.counters["triangles/s"] =
        benchmark::Counter(double(b.triangle_count), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["triangles"] = double(b.triangle_count);
    state.counters["brick"] = double(b.id);
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(b.mesh.length));
}

std::string ReadSection(const Data& d, const store::BrickInfo& b) {
    std::string bytes(b.mesh.length, '\0');
    NAVE_CHECK(d.file->ReadAt(b.mesh.offset, bytes.data(), bytes.size()).ok());
    return bytes;
}

void BM_Read(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    for (auto _ : state) benchmark::DoNotOptimize(ReadSection(*d, *b).data());
    SetRate(state, *b);
}

void BM_Checksum(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    const std::string bytes = ReadSection(*d, *b);
    for (auto _ : state) benchmark::DoNotOptimize(Checksum64(bytes.data(), bytes.size()));
    SetRate(state, *b);
}

/// Draco alone: the library's rate on this brick's bitstream (after nave's 16-byte prefix).
void BM_DracoDecode(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    const std::string bytes = ReadSection(*d, *b);
    for (auto _ : state) {
        draco::DecoderBuffer buffer;
        buffer.Init(bytes.data() + store::codec::kMeshPrefixBytes,
                    bytes.size() - store::codec::kMeshPrefixBytes);
        draco::Decoder decoder;
        auto mesh = decoder.DecodeMeshFromBuffer(&buffer);
        NAVE_CHECK(mesh.ok());
        benchmark::DoNotOptimize(mesh.value().get());
    }
    SetRate(state, *b);
}

/// nave's decode: Draco plus the copy into the BrickMesh the renderer uses.
void BM_DecodeBrick(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    const std::string bytes = ReadSection(*d, *b);
    for (auto _ : state) {
        auto mesh = store::codec::DecodeMeshSection(bytes, d->store->header().grid,
                                                    d->store->materials().size(), "bench");
        NAVE_CHECK(mesh.ok()) << mesh.status().ToString();
        benchmark::DoNotOptimize(mesh->positions.data());
    }
    SetRate(state, *b);
}

/// What the brick would cost to decode if stored otherwise: re-encoded from its decoded mesh with
/// Draco speed state.range(1), without normals (state.range(2)), with sequential connectivity
/// (state.range(3)); counters give the bytes per triangle of that encoding.
void BM_ReencodedDecode(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    auto decoded = d->store->ReadBrick(b->id);
    NAVE_CHECK(decoded.ok());
    store::BrickMesh mesh = std::move(decoded).value();
    if (state.range(2) != 0) mesh.normals.clear();
    store::EncodeOptions options;
    options.draco_speed = int(state.range(1));
    options.sequential = state.range(3) != 0;
    auto encoded = store::codec::EncodeMeshSection(mesh, d->store->header().grid, options);
    NAVE_CHECK(encoded.ok()) << encoded.status().ToString();
    for (auto _ : state) {
        auto m = store::codec::DecodeMeshSection(encoded->bytes, d->store->header().grid,
                                                 d->store->materials().size(), "bench");
        NAVE_CHECK(m.ok()) << m.status().ToString();
        benchmark::DoNotOptimize(m->positions.data());
    }
    SetRate(state, *b);
    state.counters["bytes/triangle"] = double(encoded->bytes.size()) / double(b->triangle_count);
    state.counters["vertices/triangle"] = double(encoded->vertex_count) / double(b->triangle_count);
}

/// Embree alone: a BVH over the decoded brick. Args: size class, quality (0 low, 1 medium, 2 high),
/// compact nodes, threads (0: all).
void BM_EmbreeBuild(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    auto decoded = d->store->ReadBrick(b->id);
    NAVE_CHECK(decoded.ok());
    store::BrickMesh mesh = std::move(decoded).value();
    mesh.positions.reserve(mesh.positions.size() + 1);  // Embree's 16-byte vertex loads
    const RTCBuildQuality quality = state.range(1) == 0   ? RTC_BUILD_QUALITY_LOW
                                    : state.range(1) == 1 ? RTC_BUILD_QUALITY_MEDIUM
                                                          : RTC_BUILD_QUALITY_HIGH;
    const int threads = int(state.range(3));
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    RTCDevice dev = static_cast<RTCDevice>(d->device->handle());
    int64_t bvh_bytes = 0, build_peak = 0;
    for (auto _ : state) {
        arena.execute([&] {
            const int64_t before = g_embree_bytes.load();
            g_embree_peak.store(before);
            RTCScene scene = rtcNewScene(dev);
            rtcSetSceneFlags(scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST |
                                                  (state.range(2) ? RTC_SCENE_FLAG_COMPACT : 0)));
            rtcSetSceneBuildQuality(scene, quality);
            RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       mesh.positions.data(), 0, sizeof(Vec3f),
                                       mesh.positions.size());
            rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                       mesh.indices.data(), 0, 3 * sizeof(uint32_t),
                                       mesh.TriangleCount());
            rtcSetGeometryBuildQuality(geom, quality);
            rtcCommitGeometry(geom);
            rtcAttachGeometry(scene, geom);
            rtcReleaseGeometry(geom);
            rtcCommitScene(scene);
            bvh_bytes = g_embree_bytes.load() - before;
            build_peak = g_embree_peak.load() - before;
            rtcReleaseScene(scene);
        });
    }
    SetRate(state, *b);
    state.counters["bvh_bytes/triangle"] = double(bvh_bytes) / double(b->triangle_count);
    state.counters["build_peak_bytes/triangle"] = double(build_peak) / double(b->triangle_count);
}

/// The whole load as the renderer makes it (read, checksum, decode, ResidentBrick::Build) inside an
/// arena of state.range(1) threads (0: all), BVH quality state.range(2) (0 low, 1 medium), compact
/// nodes state.range(3).
void BM_WholeLoad(benchmark::State& state) {
    const Data* d;
    const store::BrickInfo* b = Brick(state, &d);
    if (b == nullptr) return;
    const int threads = int(state.range(1));
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    render::BvhSettings bvh;
    bvh.quality = state.range(2) == 0 ? render::BvhSettings::Quality::kLow
                                      : render::BvhSettings::Quality::kMedium;
    bvh.compact = state.range(3) != 0;
    uint64_t resident = 0;
    for (auto _ : state) {
        arena.execute([&] {
            auto mesh = d->store->ReadBrick(b->id);
            NAVE_CHECK(mesh.ok()) << mesh.status().ToString();
            auto brick = render::ResidentBrick::Build(*d->device, b->id, Bounds3f(),
                                                      std::move(mesh).value(), nullptr, bvh);
            NAVE_CHECK(brick.ok()) << brick.status().ToString();
            resident = (*brick)->memory_bytes();
        });
    }
    SetRate(state, *b);
    state.counters["resident_bytes/triangle"] = double(resident) / double(b->triangle_count);
}

void SizeClasses(benchmark::internal::Benchmark* bench) {
    bench->ArgName("size")->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
}

void BuildVariants(benchmark::internal::Benchmark* bench) {
    for (int size : {0, 1, 2}) {
        for (int quality : {0, 1, 2}) {
            for (int compact : {0, 1}) {
                for (int threads : {1, 0}) bench->Args({size, quality, compact, threads});
            }
        }
    }
    bench->ArgNames({"size", "quality", "compact", "threads"})
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

void LoadVariants(benchmark::internal::Benchmark* bench) {
    for (int size : {0, 1, 2}) {
        for (int threads : {1, 0}) {
            for (int quality : {0, 1}) {
                for (int compact : {0, 1}) bench->Args({size, threads, quality, compact});
            }
        }
    }
    bench->ArgNames({"size", "threads", "quality", "compact"})
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
}

BENCHMARK(BM_Read)->Apply(SizeClasses);
BENCHMARK(BM_Checksum)->Apply(SizeClasses);
BENCHMARK(BM_DracoDecode)->Apply(SizeClasses);
BENCHMARK(BM_DecodeBrick)->Apply(SizeClasses);
BENCHMARK(BM_ReencodedDecode)
    ->ArgsProduct({{1}, {6, 10}, {0, 1}, {0, 1}})
    ->ArgNames({"size", "speed", "no_normals", "sequential"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_EmbreeBuild)->Apply(BuildVariants);
BENCHMARK(BM_WholeLoad)->Apply(LoadVariants);

}  // namespace
}  // namespace nave

// NAVE_BENCH_WARM_MALLOC=1 keeps freed blocks of up to 256 MiB on glibc's heap (no fresh mmap, so
// no page faults on reuse), to separate the cost of first-touching memory from the work itself.
int main(int argc, char** argv) {
    if (std::getenv("NAVE_BENCH_WARM_MALLOC") != nullptr) {
        mallopt(M_MMAP_THRESHOLD, 256 << 20);
        mallopt(M_TRIM_THRESHOLD, 1 << 30);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
