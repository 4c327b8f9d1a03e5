#include "store/testing/store_testing.h"

#include <cmath>
#include <numbers>
#include <random>

namespace nave::store::testing {
namespace {

// Builds a kd-tree over the cell index box [lo, hi) (cells, not coordinates), splitting the longest
// index range in the middle; leaves hold the linear cell index.
uint32_t BuildCellTree(const Bounds3f& bounds, Vec3i n, Vec3i lo, Vec3i hi,
                       std::vector<BrickTreeNode>& nodes) {
    const uint32_t index = uint32_t(nodes.size());
    nodes.emplace_back();
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    }
    if (hi[axis] - lo[axis] <= 1) {
        nodes[index].axis = 3;
        nodes[index].brick = uint32_t(lo.x + n.x * (lo.y + n.y * lo.z));
        return index;
    }
    const int mid = (lo[axis] + hi[axis]) / 2;
    const float split =
        bounds.min[axis] + (bounds.max[axis] - bounds.min[axis]) * float(mid) / float(n[axis]);
    Vec3i below_hi = hi, above_lo = lo;
    below_hi[axis] = mid;
    above_lo[axis] = mid;
    const uint32_t below = BuildCellTree(bounds, n, lo, below_hi, nodes);
    const uint32_t above = BuildCellTree(bounds, n, above_lo, hi, nodes);
    nodes[index].axis = uint8_t(axis);
    nodes[index].split = split;
    nodes[index].child[0] = below;
    nodes[index].child[1] = above;
    return index;
}

}  // namespace

BrickMesh MakeSurface(const SurfaceOptions& o) {
    BrickMesh mesh;
    const uint32_t vx = o.quads_x + 1, vy = o.quads_y + 1;
    const float k = 2.f * std::numbers::pi_v<float> / o.size_m;  // one period across the surface
    std::mt19937 rng(o.seed);
    std::uniform_real_distribution<float> unit(0.f, 1.f);
    for (uint32_t j = 0; j < vy; ++j) {
        for (uint32_t i = 0; i < vx; ++i) {
            float u = float(i) / float(o.quads_x), v = float(j) / float(o.quads_y);
            if (o.jitter > 0 && i > 0 && j > 0 && i < o.quads_x && j < o.quads_y) {
                u += o.jitter * (unit(rng) - 0.5f) / float(o.quads_x);
                v += o.jitter * (unit(rng) - 0.5f) / float(o.quads_y);
            }
            const float x = u * o.size_m, y = v * o.size_m;
            const float z = o.amplitude_m * std::sin(k * x) * std::cos(k * y);
            mesh.positions.push_back({x, y, z});
            if (o.normals) {
                // n = (-dz/dx, -dz/dy, 1), normalized.
                const float dzdx = o.amplitude_m * k * std::cos(k * x) * std::cos(k * y);
                const float dzdy = -o.amplitude_m * k * std::sin(k * x) * std::sin(k * y);
                mesh.normals.push_back(Normalize(Vec3f{-dzdx, -dzdy, 1.f}));
            }
            if (o.uvs) mesh.uvs.push_back({u, v});
        }
    }
    for (uint32_t j = 0; j < o.quads_y; ++j) {
        for (uint32_t i = 0; i < o.quads_x; ++i) {
            const uint32_t a = j * vx + i, b = a + 1, c = a + vx, d = c + 1;
            const uint32_t material =
                o.material_count == 0 ? 0 : (i * o.material_count / o.quads_x);
            if (o.jitter > 0 && unit(rng) < 0.5f) {
                mesh.indices.insert(mesh.indices.end(), {a, b, c, b, d, c});
            } else {
                mesh.indices.insert(mesh.indices.end(), {a, b, d, a, d, c});
            }
            mesh.material_ids.insert(mesh.material_ids.end(), {material, material});
        }
    }
    return mesh;
}

std::vector<MaterialRecord> MakeMaterials(uint32_t count) {
    std::vector<MaterialRecord> materials(count);
    for (uint32_t i = 0; i < count; ++i) {
        MaterialRecord& m = materials[i];
        m.name = fmt::format("m{}", i);
        m.diffuse = {0.1f * float(i % 10), 0.5f, 1.f - 0.05f * float(i % 20)};
        m.ior = 1.3f + 0.01f * float(i);
        m.roughness = 0.5f;
        if (i % 2 == 1) m.textures["map_Kd"] = fmt::format("textures/m{}.png", i);
    }
    return materials;
}

GridStore SplitOnGrid(const BrickMesh& mesh, Vec3i cells) {
    Bounds3f bounds;
    for (const Vec3f& p : mesh.positions) bounds.Extend(p);
    // Pad so that no centroid lies on the outer faces' far side and flat models get thick cells.
    const Vec3f pad = bounds.Diagonal() * 0.01f + Vec3f{1e-3f, 1e-3f, 1e-3f};
    bounds = Bounds3f(bounds.min - pad, bounds.max + pad);

    std::vector<BrickTreeNode> nodes;
    BuildCellTree(bounds, cells, {0, 0, 0}, cells, nodes);
    const uint32_t cell_count = uint32_t(cells.x * cells.y * cells.z);
    BrickTree cell_tree(bounds, nodes);

    // Triangles to cells by centroid, with the tree's own rule for points on a split plane.
    std::vector<std::vector<uint32_t>> by_cell(cell_count);
    for (size_t t = 0; t < mesh.TriangleCount(); ++t) {
        const Vec3f c =
            (mesh.positions[mesh.indices[3 * t]] + mesh.positions[mesh.indices[3 * t + 1]] +
             mesh.positions[mesh.indices[3 * t + 2]]) /
            3.f;
        by_cell[cell_tree.Locate(c)].push_back(uint32_t(t));
    }
    GridStore out;
    std::vector<uint32_t> brick_of_cell(cell_count, kNoBrick);
    for (uint32_t cell = 0; cell < cell_count; ++cell) {
        if (by_cell[cell].empty()) continue;
        brick_of_cell[cell] = uint32_t(out.bricks.size());
        BrickMesh brick;
        std::vector<uint32_t> local(mesh.VertexCount(), kNoBrick);
        for (uint32_t t : by_cell[cell]) {
            for (int c = 0; c < 3; ++c) {
                const uint32_t v = mesh.indices[3 * size_t(t) + c];
                if (local[v] == kNoBrick) {
                    local[v] = uint32_t(brick.positions.size());
                    brick.positions.push_back(mesh.positions[v]);
                    if (mesh.HasNormals()) brick.normals.push_back(mesh.normals[v]);
                    if (mesh.HasUvs()) brick.uvs.push_back(mesh.uvs[v]);
                }
                brick.indices.push_back(local[v]);
            }
            brick.material_ids.push_back(mesh.material_ids[t]);
        }
        out.bricks.push_back(std::move(brick));
        out.triangles.push_back(by_cell[cell]);
    }
    for (BrickTreeNode& n : nodes) {
        if (n.IsLeaf()) n.brick = brick_of_cell[n.brick];
    }
    out.tree = BrickTree(bounds, std::move(nodes));
    return out;
}

StatusOr<GridStore> WriteGridStore(const std::filesystem::path& path, const BrickMesh& mesh,
                                   const std::vector<MaterialRecord>& materials, Vec3i cells,
                                   const GlobalGrid& grid, const EncodeOptions& options) {
    GridStore split = SplitOnGrid(mesh, cells);
    StoreProvenance provenance{{"synthetic-surface"}, "nave test", "grid-split"};
    NAVE_ASSIGN_OR_RETURN(auto writer, StoreWriter::Create(path, grid, provenance));
    const std::vector<Bounds3f> cell_boxes = split.tree.BrickCells(uint32_t(split.bricks.size()));
    for (size_t b = 0; b < split.bricks.size(); ++b) {
        NAVE_ASSIGN_OR_RETURN(EncodedBrick encoded,
                              EncodeBrick(split.bricks[b], cell_boxes[b], grid, options));
        NAVE_ASSIGN_OR_RETURN(uint32_t id, writer->Append(encoded));
        NAVE_CHECK_EQ(id, uint32_t(b));
    }
    NAVE_RETURN_IF_ERROR(writer->Finish(materials, split.tree, mesh.TriangleCount()));
    return split;
}

}  // namespace nave::store::testing
