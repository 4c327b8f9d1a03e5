#include "src/render/transport/transport_common.h"

namespace nave::render {

Status ForEachOwnedTriangle(
    const RenderScene& scene, StreamScheduler& scheduler, ScanDetail detail,
    const std::function<bool(const SurfaceMaterial&)>& want,
    const std::function<void(const ResidentMesh&, size_t, uint32_t)>& visit) {
    const store::BrickTree& tree = scheduler.tree();
    return scheduler.ForEachBrick(
        "model scan", detail, [&](uint32_t b, const ResidentBrick& brick) {
            const ResidentMesh& m = brick.mesh();
            for (size_t t = 0; t < m.TriangleCount(); ++t) {
                const uint32_t mat = m.material_ids[t];
                if (mat >= scene.materials.size() || !want(scene.materials[mat])) continue;
                const std::array<Vec3f, 3> v = m.TrianglePositions(t);
                if (tree.Locate((v[0] + v[1] + v[2]) * (1.f / 3.f)) == b) visit(m, t, b);
            }
            return Status::Ok();
        });
}

}  // namespace nave::render
