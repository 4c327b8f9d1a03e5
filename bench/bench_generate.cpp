// The procedural abbey's generator alone: triangles per second as preprocess consumes them (batches
// through the TriangleSource interface), by detail and producer threads. Counters: triangles/s,
// triangles per run. NAVE_BENCH_DETAIL=D adds a run at detail D (the 1 B-triangle abbey: D = 1250,
// docs/abbey.md), which takes a minute or two.
//
//     build/release/bench/bench_generate

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <vector>

#include "preprocess/abbey/abbey_source.h"
#include "src/core/check.h"

namespace nave::preprocess {
namespace {

void BM_AbbeyGenerate(benchmark::State& state) {
    const double detail = double(state.range(0));
    const int threads = int(state.range(1));
    uint64_t triangles = 0;
    for (auto _ : state) {
        std::unique_ptr<TriangleSource> source = MakeAbbeySource(detail, threads);
        std::vector<Triangle> batch;
        triangles = 0;
        for (;;) {
            StatusOr<bool> more = source->Next(batch, size_t(1) << 16);
            NAVE_CHECK(more.ok()) << more.status().ToString();
            if (!*more) break;
            triangles += batch.size();
        }
    }
    state.counters["triangles"] = double(triangles);
    state.counters["triangles/s"] = benchmark::Counter(
        double(triangles) * double(state.iterations()), benchmark::Counter::kIsRate);
}

void Details(benchmark::internal::Benchmark* b) {
    b->ArgNames({"detail", "threads"});
    for (int threads : {1, 2}) {
        for (int detail : {1, 9, 110}) b->Args({detail, threads});
        if (const char* d = std::getenv("NAVE_BENCH_DETAIL")) b->Args({std::atoi(d), threads});
    }
}
BENCHMARK(BM_AbbeyGenerate)->Apply(Details)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace
}  // namespace nave::preprocess

BENCHMARK_MAIN();
