#include "src/render/bricks/grid_bricks.h"

#include <functional>
#include <unordered_map>

namespace nave::render {

GridBricks SplitIntoGridBricks(const store::BrickMesh& mesh, int nx, int ny, int nz) {
    Bounds3f box;
    for (const Vec3f& p : mesh.positions) box.Extend(p);
    // Enlarge a little so no vertex lies on the root box (the tree tiles exactly this box).
    Vec3f pad = box.Diagonal() * 1e-3f + Vec3f(1e-4f, 1e-4f, 1e-4f);
    box = Bounds3f(box.min - pad, box.max + pad);
    const int n[3] = {nx, ny, nz};
    std::vector<float> planes[3];
    for (int a = 0; a < 3; ++a) {
        for (int i = 0; i <= n[a]; ++i) {
            planes[a].push_back(
                i == n[a] ? box.max[a] : box.min[a] + box.Diagonal()[a] * float(i) / float(n[a]));
        }
    }
    auto cell_index = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
    // Triangles to cells by box overlap (closed boxes: a triangle on a plane goes to both sides).
    std::vector<std::vector<uint32_t>> cell_tris(size_t(nx) * ny * nz);
    for (size_t t = 0; t < mesh.TriangleCount(); ++t) {
        Bounds3f tb;
        for (int c = 0; c < 3; ++c) tb.Extend(mesh.positions[mesh.indices[3 * t + c]]);
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = 0;
            while (lo[a] + 1 < n[a] && planes[a][lo[a] + 1] < tb.min[a]) ++lo[a];
            hi[a] = lo[a];
            while (hi[a] + 1 < n[a] && planes[a][hi[a] + 1] <= tb.max[a]) ++hi[a];
        }
        for (int k = lo[2]; k <= hi[2]; ++k)
            for (int j = lo[1]; j <= hi[1]; ++j)
                for (int i = lo[0]; i <= hi[0]; ++i)
                    cell_tris[cell_index(i, j, k)].push_back(uint32_t(t));
    }
    GridBricks out;
    std::vector<uint32_t> brick_of_cell(cell_tris.size(), store::kNoBrick);
    for (size_t c = 0; c < cell_tris.size(); ++c) {
        if (cell_tris[c].empty()) continue;
        brick_of_cell[c] = uint32_t(out.meshes.size());
        store::BrickMesh m;
        std::unordered_map<uint32_t, uint32_t> remap;
        for (uint32_t t : cell_tris[c]) {
            for (int v = 0; v < 3; ++v) {
                uint32_t src = mesh.indices[3 * t + v];
                auto [it, inserted] = remap.try_emplace(src, uint32_t(m.positions.size()));
                if (inserted) {
                    m.positions.push_back(mesh.positions[src]);
                    if (mesh.HasNormals()) m.normals.push_back(mesh.normals[src]);
                    if (mesh.HasUvs()) m.uvs.push_back(mesh.uvs[src]);
                }
                m.indices.push_back(it->second);
            }
            m.material_ids.push_back(mesh.material_ids[t]);
        }
        out.meshes.push_back(std::move(m));
    }
    // A kd-tree over the grid: split the longest index range in the middle until one cell is left.
    std::vector<store::BrickTreeNode> nodes;
    struct Range {
        int lo[3], hi[3];
    };
    std::function<uint32_t(Range)> build = [&](Range r) -> uint32_t {
        uint32_t index = uint32_t(nodes.size());
        nodes.emplace_back();
        int axis = -1, longest = 1;
        for (int a = 0; a < 3; ++a) {
            if (r.hi[a] - r.lo[a] > longest) {
                longest = r.hi[a] - r.lo[a];
                axis = a;
            }
        }
        if (axis < 0) {
            nodes[index].brick = brick_of_cell[cell_index(r.lo[0], r.lo[1], r.lo[2])];
            return index;
        }
        int mid = (r.lo[axis] + r.hi[axis]) / 2;
        Range below = r, above = r;
        below.hi[axis] = mid;
        above.lo[axis] = mid;
        uint32_t c0 = build(below);
        uint32_t c1 = build(above);
        nodes[index].axis = uint8_t(axis);
        nodes[index].split = planes[axis][mid];
        nodes[index].child[0] = c0;
        nodes[index].child[1] = c1;
        return index;
    };
    build(Range{{0, 0, 0}, {nx, ny, nz}});
    out.tree = store::BrickTree(box, std::move(nodes));
    return out;
}

}  // namespace nave::render
