// The pager's decision cost (docs/pager.md): choosing the next brick among N, pinning a resident
// brick, and a load that must first choose and evict a victim, for models of 256 to 65536 bricks.
// Bricks are single triangles so that the load itself (copy + Embree build) costs little next to
// the decisions.
//   build/release/bench/bench_pager --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <random>

#include "src/render/bricks/brick_source.h"
#include "src/render/bricks/memory_brick_source.h"
#include "src/render/stream/pager.h"
#include "store/brick_tree.h"

namespace nave::render {
namespace {

/// N one-triangle bricks in a row, each in its own cell.
std::unique_ptr<MemoryBrickSource> TinyBricks(uint32_t n) {
    std::vector<store::BrickTreeNode> nodes;
    std::vector<store::BrickMesh> meshes;
    // A left-leaning chain of splits along x: cell i is [i, i + 1).
    std::function<uint32_t(uint32_t, uint32_t)> build = [&](uint32_t lo, uint32_t hi) -> uint32_t {
        uint32_t index = uint32_t(nodes.size());
        nodes.emplace_back();
        if (hi - lo == 1) {
            nodes[index].brick = lo;
            return index;
        }
        uint32_t mid = (lo + hi) / 2;
        uint32_t c0 = build(lo, mid), c1 = build(mid, hi);
        nodes[index].axis = 0;
        nodes[index].split = float(mid);
        nodes[index].child[0] = c0;
        nodes[index].child[1] = c1;
        return index;
    };
    build(0, n);
    for (uint32_t i = 0; i < n; ++i) {
        store::BrickMesh m;
        float x = float(i) + 0.25f;
        m.positions = {{x, 0.25f, 0.5f}, {x + 0.5f, 0.25f, 0.5f}, {x, 0.75f, 0.5f}};
        m.indices = {0, 1, 2};
        m.material_ids = {0};
        meshes.push_back(std::move(m));
    }
    auto device = EmbreeDevice::Create("threads=1");
    store::BrickTree tree(Bounds3f({0, 0, 0}, {float(n), 1, 1}), std::move(nodes));
    return std::make_unique<MemoryBrickSource>(*device, std::move(tree), std::move(meshes),
                                               std::vector<store::MaterialRecord>(1));
}

std::vector<size_t> RandomWaiting(uint32_t n) {
    std::mt19937 rng(7);
    std::vector<size_t> waiting(n);
    for (auto& w : waiting) w = rng() % 5000;
    return waiting;
}

void BM_PagerPick(benchmark::State& state) {
    const uint32_t n = uint32_t(state.range(0));
    auto source = TinyBricks(n);
    std::vector<size_t> waiting = RandomWaiting(n);
    PagerOptions options;
    options.prefetch = false;
    options.brick_budget_bytes = MinimumBrickBudget(*source, false).total_bytes / 4;
    auto pager = Pager::Create(*source, options, [&](uint32_t b) { return waiting[b]; });
    for (uint32_t b = 0; b < n; b += 8) (void)(*pager)->Acquire(b);  // some resident bricks
    for (auto _ : state) benchmark::DoNotOptimize((*pager)->Pick(waiting));
    state.SetItemsProcessed(int64_t(state.iterations()));
    state.counters["bricks"] = n;
}
BENCHMARK(BM_PagerPick)->Arg(256)->Arg(4096)->Arg(65536);

void BM_PagerAcquireResident(benchmark::State& state) {
    const uint32_t n = uint32_t(state.range(0));
    auto source = TinyBricks(n);
    PagerOptions options;
    options.prefetch = false;
    options.brick_budget_bytes = MinimumBrickBudget(*source, false).total_bytes;
    auto pager = Pager::Create(*source, options, {});
    (void)(*pager)->Acquire(n / 2);
    for (auto _ : state) {
        auto h = (*pager)->Acquire(n / 2);
        benchmark::DoNotOptimize(h);
    }
    state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_PagerAcquireResident)->Arg(4096);

void BM_PagerLoadWithEviction(benchmark::State& state) {
    // Half the bricks fit: every acquire of the sweep loads one brick and evicts one, chosen among
    // the resident half by queue length then age.
    const uint32_t n = uint32_t(state.range(0));
    auto source = TinyBricks(n);
    std::vector<size_t> waiting = RandomWaiting(n);
    PagerOptions options;
    options.prefetch = false;
    options.brick_budget_bytes = MinimumBrickBudget(*source, false).total_bytes / 2;
    auto pager = Pager::Create(*source, options, [&](uint32_t b) { return waiting[b]; });
    uint32_t next = 0;
    for (auto _ : state) {
        auto h = (*pager)->Acquire(next);
        benchmark::DoNotOptimize(h);
        next = (next + 1) % n;
    }
    state.SetItemsProcessed(int64_t(state.iterations()));
    state.counters["evictions"] = double((*pager)->stats().evictions);
}
BENCHMARK(BM_PagerLoadWithEviction)->Arg(256)->Arg(4096);

}  // namespace
}  // namespace nave::render

BENCHMARK_MAIN();
