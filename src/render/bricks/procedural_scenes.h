#pragma once
// Small procedural models for test scenes (configs/test_*.toml), benchmarks and tests, rendered
// without a store: `nave render --procedural caustic:bricks=4 --config configs/test_caustic.toml -o
// out.exr`.

#include <memory>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/bricks/memory_brick_source.h"
#include "store/brick_mesh.h"

namespace nave::render {

struct ProceduralModel {
    store::BrickMesh mesh;
    std::vector<std::string> material_names;  ///< by material id
};

/// "furnace": a closed sphere (r = 1 m, inward-facing, material "shell").
/// "caustic": a 10 m floor ("floor") with a glass ball ("glass", r = 0.5 m) and a diffuse ball
/// ("ball"). "clutter": floor, two balls, a box (materials "floor", "ball", "chrome").
StatusOr<ProceduralModel> MakeProceduralModel(const std::string& name);

/// Parses "NAME[:bricks=N]" and returns an in-memory source cut into N^3 bricks (default 1).
StatusOr<std::unique_ptr<MemoryBrickSource>> OpenProceduralSource(
    const std::string& spec, std::shared_ptr<EmbreeDevice> device);

}  // namespace nave::render
