#include "src/render/bricks/procedural_scenes.h"

#include "src/render/bricks/grid_bricks.h"
#include "src/render/bricks/memory_brick_source.h"
#include "src/render/bricks/procedural_meshes.h"

namespace nave::render {

StatusOr<ProceduralModel> MakeProceduralModel(const std::string& name) {
    ProceduralModel m;
    if (name == "furnace") {
        AppendSphere(&m.mesh, {0, 0, 0}, 1.0f, 24, 48, 0, /*inward=*/true);
        m.material_names = {"shell"};
    } else if (name == "caustic") {
        AppendQuad(&m.mesh, {0, 0, 0}, {5, 0, 0}, {0, 5, 0}, 8, 0);
        AppendSphere(&m.mesh, {0, 0, 0.6f}, 0.5f, 48, 96, 1);
        AppendSphere(&m.mesh, {-1.4f, 0.8f, 0.4f}, 0.4f, 24, 48, 2);
        m.material_names = {"floor", "glass", "ball"};
    } else if (name == "clutter") {
        AppendQuad(&m.mesh, {0, 0, 0}, {4, 0, 0}, {0, 4, 0}, 6, 0);
        AppendSphere(&m.mesh, {0.5f, 0.3f, 1.0f}, 0.8f, 16, 32, 1);
        AppendSphere(&m.mesh, {-1.5f, -1.0f, 0.6f}, 0.6f, 12, 24, 2);
        AppendBox(&m.mesh, Bounds3f({1.0f, -2.5f, 0.01f}, {2.5f, -1.2f, 1.8f}), 0);
        m.material_names = {"floor", "ball", "chrome"};
    } else {
        return InvalidArgumentError(
            "--procedural: unknown model '{}' (expected furnace, caustic or clutter)", name);
    }
    return m;
}

StatusOr<std::unique_ptr<MemoryBrickSource>> OpenProceduralSource(
    const std::string& spec, std::shared_ptr<EmbreeDevice> device) {
    std::string name = spec;
    int bricks = 1;
    size_t colon = spec.find(':');
    if (colon != std::string::npos) {
        name = spec.substr(0, colon);
        std::string opt = spec.substr(colon + 1);
        if (opt.rfind("bricks=", 0) != 0 || std::sscanf(opt.c_str() + 7, "%d", &bricks) != 1 ||
            bricks < 1 || bricks > 64) {
            return InvalidArgumentError(
                "--procedural {}: expected NAME[:bricks=N] with N in [1, 64], found '{}'", spec,
                opt);
        }
    }
    NAVE_ASSIGN_OR_RETURN(ProceduralModel model, MakeProceduralModel(name));
    GridBricks grid = SplitIntoGridBricks(model.mesh, bricks, bricks, bricks);
    std::vector<store::MaterialRecord> materials;
    for (const auto& n : model.material_names) {
        store::MaterialRecord r;
        r.name = n;
        materials.push_back(r);
    }
    return std::make_unique<MemoryBrickSource>(std::move(device), grid.tree, std::move(grid.meshes),
                                               std::move(materials));
}

}  // namespace nave::render
