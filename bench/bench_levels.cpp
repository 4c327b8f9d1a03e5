// Levels of detail made from real bricks (store/brick_levels.h): the simplification that
// `nave preprocess --levels` adds to every brick's encoding, on one thread. The bricks are the
// procedural abbey's at detail 9 (NAVE_BENCH_DETAIL=D for another), preprocessed without levels
// into a temporary store once per run and decoded whole; each iteration makes every brick's levels.
// Counters: full-detail triangles/s in, the shares of them levels 1 and 2 keep, bricks with a
// level 2.
// Results and the command: docs/preprocess.md, "Levels of detail: what they cost".
//
//     build/release/bench/bench_levels

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "preprocess/preprocess.h"
#include "src/core/check.h"
#include "store/brick_levels.h"
#include "store/store_reader.h"

namespace nave::store {
namespace {

/// The abbey's bricks at full detail, generated and decoded once.
struct Bricks {
    std::vector<BrickMesh> meshes;
    std::vector<Bounds3f> cells;
};
const Bricks& AbbeyBricks() {
    static const Bricks bricks = [] {
        const char* d = std::getenv("NAVE_BENCH_DETAIL");
        const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                          ("nave-bench-levels-" + std::to_string(getpid()));
        std::filesystem::create_directories(dir);
        preprocess::PreprocessOptions options;
        options.generate = std::string("abbey:detail=") + (d ? d : "9");
        options.output = dir / "abbey.nave";
        options.convert_textures = false;
        options.verify_every = 0;
        const StatusOr<preprocess::PreprocessStats> stats = preprocess::RunPreprocess(options);
        NAVE_CHECK(stats.ok()) << stats.status().ToString();
        StatusOr<std::unique_ptr<Store>> store = Store::Open(options.output);
        NAVE_CHECK(store.ok()) << store.status().ToString();
        Bricks out;
        for (uint32_t b = 0; b < (*store)->bricks().size(); ++b) {
            StatusOr<BrickMesh> mesh = (*store)->ReadBrick(b);
            NAVE_CHECK(mesh.ok()) << mesh.status().ToString();
            out.meshes.push_back(std::move(*mesh));
            out.cells.push_back((*store)->bricks()[b].cell);
        }
        std::filesystem::remove_all(dir);
        return out;
    }();
    return bricks;
}

void BM_MakeBrickLevels(benchmark::State& state) {
    const Bricks& all = AbbeyBricks();
    const std::vector<BrickMesh>& bricks = all.meshes;
    LevelOptions options;
    uint64_t input = 0, level1 = 0, level2 = 0, second_levels = 0;
    for (auto _ : state) {
        input = level1 = level2 = second_levels = 0;
        for (size_t b = 0; b < bricks.size(); ++b) {
            const BrickMesh& mesh = bricks[b];
            const std::vector<BrickLevel> levels = MakeBrickLevels(mesh, options, &all.cells[b]);
            input += mesh.TriangleCount();
            if (levels.size() > 1) level2 += levels[1].mesh.TriangleCount();
            if (!levels.empty()) level1 += levels[0].mesh.TriangleCount();
            second_levels += levels.size() > 1 ? 1 : 0;
        }
    }
    state.counters["bricks"] = double(bricks.size());
    state.counters["triangles"] = double(input);
    state.counters["triangles/s"] =
        benchmark::Counter(double(input) * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["level1_share"] = input ? double(level1) / double(input) : 0.0;
    state.counters["level2_share"] = input ? double(level2) / double(input) : 0.0;
    state.counters["level2_bricks"] = double(second_levels);
}
BENCHMARK(BM_MakeBrickLevels)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace
}  // namespace nave::store

BENCHMARK_MAIN();
