#include "store/brick_levels.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "src/core/key_table.h"
#include "store/brick_codec.h"

namespace nave::store {
namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "meshoptimizer reads positions as float[3]");

constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();

/// meshoptimizer's error is an estimate from its quadrics, not a bound: on curved test sheets the
/// centres of coarse triangles lay up to 1.47 times as far from the full surface. The renderer
/// chooses levels and keeps rays clear of the other levels' surfaces by the recorded error, so the
/// store records twice the estimate.
constexpr float kErrorSafety = 2.f;

/// The triangles of one material, as indices into the mesh's vertices.
struct Submesh {
    uint32_t material = 0;
    std::vector<uint32_t> triangles;  ///< triangle numbers in the mesh, in order
};

/// Groups the triangles of `mesh` by material, by ascending material id (so the levels' bytes do
/// not depend on anything but the mesh).
std::vector<Submesh> SplitByMaterial(const BrickMesh& mesh) {
    std::vector<uint32_t> order(mesh.TriangleCount());
    for (uint32_t t = 0; t < order.size(); ++t) order[t] = t;
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return mesh.material_ids[a] < mesh.material_ids[b];
    });
    std::vector<Submesh> out;
    for (uint32_t t : order) {
        if (out.empty() || out.back().material != mesh.material_ids[t])
            out.push_back({mesh.material_ids[t], {}});
        out.back().triangles.push_back(t);
    }
    return out;
}

/// Reused between submeshes: a vertex's index in the current submesh, kUnused elsewhere.
struct Scratch {
    std::vector<uint32_t> local_of;
    std::vector<uint32_t> global_of;
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices;
    std::vector<uint32_t> simplified;
    /// Per vertex of the source mesh: whether it must stay where it is (LockedVertices).
    std::vector<bool> locked;
};

/// The area of the triangles `indices` (into `positions`) form.
double SurfaceArea(const std::vector<Vec3f>& positions, const uint32_t* indices, size_t count) {
    double area = 0;
    for (size_t i = 0; i + 2 < count; i += 3) {
        const Vec3f& a = positions[indices[i]];
        area += 0.5 *
                double(Length(Cross(positions[indices[i + 1]] - a, positions[indices[i + 2]] - a)));
    }
    return area;
}

/// How many times a material whose area a level changes too much is simplified again, each time
/// toward half the error before, before it is kept whole.
constexpr int kAreaRetries = 3;

/// Simplifies one material's triangles of `mesh` as far as `target_error` (model units) allows
/// while their area changes by at most `max_area_change`, appending the kept triangles (indices
/// into `mesh`'s vertices) to `out`. Returns the absolute error reached: meshoptimizer's relative
/// error times its scale (the submesh's extent), since the submesh alone is simplified.
/// With `lock_borders` every border stays; otherwise s.locked (when not empty) names the vertices
/// that stay.
float SimplifySubmesh(const BrickMesh& mesh, const Submesh& sub, float target_error,
                      bool lock_borders, double max_area_change, Scratch& s, BrickMesh* out) {
    // A compact copy of the submesh's vertices: meshoptimizer's work and its scale then depend on
    // this material's vertices only.
    s.global_of.clear();
    s.positions.clear();
    s.indices.clear();
    for (uint32_t t : sub.triangles) {
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = mesh.indices[3 * size_t(t) + c];
            if (s.local_of[v] == kUnused) {
                s.local_of[v] = uint32_t(s.global_of.size());
                s.global_of.push_back(v);
                s.positions.push_back(mesh.positions[v]);
            }
            s.indices.push_back(s.local_of[v]);
        }
    }
    for (uint32_t v : s.global_of) s.local_of[v] = kUnused;
    // meshoptimizer 0.18 takes no per-vertex locks, but never moves a vertex that shares its
    // position with more than one other, nor one whose twin has no open edge to match its own
    // (its classifyVertices: Kind_Locked): an unreferenced copy of a vertex locks it.
    if (!s.locked.empty()) {
        const size_t referenced = s.positions.size();
        for (size_t l = 0; l < referenced; ++l)
            if (s.locked[s.global_of[l]]) s.positions.push_back(s.positions[l]);
    }

    const auto keep_whole = [&] {
        for (uint32_t t : sub.triangles)
            for (int c = 0; c < 3; ++c) out->indices.push_back(mesh.indices[3 * size_t(t) + c]);
        out->material_ids.insert(out->material_ids.end(), sub.triangles.size(), sub.material);
    };
    s.simplified.resize(s.indices.size());  // meshoptimizer's worst case: every index kept
    const float scale = meshopt_simplifyScale(&s.positions[0].x, s.positions.size(), sizeof(Vec3f));
    if (!(scale > 0)) {  // every vertex at one point: nothing to simplify
        keep_whole();
        return 0;
    }
    const double area = SurfaceArea(s.positions, s.indices.data(), s.indices.size());
    float target = target_error;
    for (int attempt = 0; attempt <= kAreaRetries; ++attempt, target *= 0.5f) {
        float relative_error = 0;
        // No triangle target (0): the error alone stops the collapses.
        const size_t kept = meshopt_simplify(
            s.simplified.data(), s.indices.data(), s.indices.size(), &s.positions[0].x,
            s.positions.size(), sizeof(Vec3f),
            /*target_index_count=*/0, target / scale,
            lock_borders ? unsigned(meshopt_SimplifyLockBorder) : 0u, &relative_error);
        const double kept_area = SurfaceArea(s.positions, s.simplified.data(), kept);
        if (!(std::abs(kept_area - area) > max_area_change * area)) {
            for (size_t i = 0; i < kept; ++i) out->indices.push_back(s.global_of[s.simplified[i]]);
            out->material_ids.insert(out->material_ids.end(), kept / 3, sub.material);
            return relative_error * scale;
        }
    }
    keep_whole();
    return 0;
}

/// Keeps only the vertices `level` references, in the order of their first use, with their texture
/// coordinates and, if `keep_normals`, their normals from `source`.
void CompactVertices(const BrickMesh& source, bool keep_normals, BrickMesh* level) {
    std::vector<uint32_t> remap(source.VertexCount());
    const size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), level->indices.data(),
                                                         level->indices.size(), remap.size());
    const bool normals = keep_normals && source.HasNormals();
    level->positions.resize(used);
    if (normals) level->normals.resize(used);
    if (source.HasUvs()) level->uvs.resize(used);
    for (size_t v = 0; v < remap.size(); ++v) {
        const uint32_t to = remap[v];
        if (to == kUnused) continue;
        level->positions[to] = source.positions[v];
        if (normals) level->normals[to] = source.normals[v];
        if (source.HasUvs()) level->uvs[to] = source.uvs[v];
    }
    for (uint32_t& i : level->indices) i = remap[i];
}

}  // namespace

Status ValidateLevelOptions(const LevelOptions& options) {
    const std::vector<double>& r = options.relative_errors;
    for (size_t k = 0; k < r.size(); ++k) {
        if (!(r[k] > 0 && r[k] < 1) || (k > 0 && !(r[k] > r[k - 1]))) {
            return InvalidArgumentError(
                "level {} error {}: expected a fraction of the brick's extent in (0, 1), larger "
                "than the level before's",
                k + 1, r[k]);
        }
    }
    if (!(options.max_kept_fraction > 0 && options.max_kept_fraction <= 1)) {
        return InvalidArgumentError("largest kept fraction {} out of range (0, 1]",
                                    options.max_kept_fraction);
    }
    if (!(options.max_area_change >= 0 && options.max_area_change < 1)) {
        return InvalidArgumentError("largest area change {} out of range [0, 1)",
                                    options.max_area_change);
    }
    if (!(options.max_grid_error_fraction >= 0 && options.max_grid_error_fraction < 1)) {
        return InvalidArgumentError("largest grid error fraction {} out of range [0, 1)",
                                    options.max_grid_error_fraction);
    }
    if (options.draco_speed < 0 || options.draco_speed > 10) {
        return InvalidArgumentError("levels' Draco speed {} out of range [0, 10]",
                                    options.draco_speed);
    }
    return Status::Ok();
}

uint32_t LevelGridShift(const BrickMesh& level, float error, const GlobalGrid& grid,
                        const LevelOptions& options) {
    uint32_t shift = 0;
    while (shift < codec::kMaxMeshGridShift &&
           GridSnapDistance(grid, shift + 1) <= options.max_grid_error_fraction * double(error)) {
        ++shift;
    }
    if (shift == 0 || level.TriangleCount() == 0) return 0;
    // Each material's area before snapping, then at each candidate shift, coarsest first: a snap
    // coarser than a part's size collapses it (a stud, a thin moulding) and its light with it.
    auto material_areas = [&](const std::vector<Vec3f>& positions) {
        std::vector<double> area;
        for (size_t t = 0; t < level.TriangleCount(); ++t) {
            const uint32_t m = level.material_ids[t];
            if (m >= area.size()) area.resize(size_t(m) + 1, 0.0);
            area[m] += SurfaceArea(positions, &level.indices[3 * t], 3);
        }
        return area;
    };
    const std::vector<double> before = material_areas(level.positions);
    std::vector<Vec3f> snapped(level.positions.size());
    for (; shift > 0; --shift) {
        GlobalGrid coarse = grid;
        coarse.step = grid.step * double(uint64_t(1) << shift);
        for (size_t v = 0; v < snapped.size(); ++v)
            snapped[v] = coarse.Dequantize(coarse.Quantize(level.positions[v]));
        const std::vector<double> after = material_areas(snapped);
        bool kept = true;
        for (size_t m = 0; m < before.size() && kept; ++m)
            kept = !(std::abs(after[m] - before[m]) > 0.5 * options.max_area_change * before[m]);
        if (kept) return shift;
    }
    return 0;
}

namespace {

/// The vertices of `mesh` that a level keeps in place under BorderLock::kCutAndMaterials: those
/// not strictly inside `cell`, and those whose position triangles of two materials use. A brick
/// holds every triangle whose box overlaps its cell, so a border where it was cut from its
/// neighbours has at least one end outside the cell or on a face (the missing neighbour would
/// otherwise overlap the cell too): with those ends locked, the cut border stays where it is.
std::vector<bool> LockedVertices(const BrickMesh& mesh, const Bounds3f& cell) {
    std::vector<bool> locked(mesh.VertexCount(), false);
    for (size_t v = 0; v < locked.size(); ++v) {
        const Vec3f& p = mesh.positions[v];
        for (int a = 0; a < 3; ++a)
            if (!(p[a] > cell.min[a] && p[a] < cell.max[a])) locked[v] = true;
    }
    // One number per distinct position: the decoder may give a position several vertices (Draco
    // splits them where the surface is not a manifold), and a border between materials is a
    // border of positions.
    KeyTable<std::array<uint32_t, 3>> positions;
    positions.Reset(mesh.VertexCount());
    std::vector<uint32_t> position_of(mesh.VertexCount());
    for (size_t v = 0; v < position_of.size(); ++v) {
        const Vec3f& p = mesh.positions[v];
        position_of[v] =
            positions.Insert({std::bit_cast<uint32_t>(p.x), std::bit_cast<uint32_t>(p.y),
                              std::bit_cast<uint32_t>(p.z)});
    }
    // The material of each position's first triangle, or kShared once a second one appears.
    constexpr uint32_t kShared = kUnused - 1;
    std::vector<uint32_t> material_at(positions.size(), kUnused);
    for (size_t t = 0; t < mesh.TriangleCount(); ++t) {
        const uint32_t m = mesh.material_ids[t];
        for (int c = 0; c < 3; ++c) {
            uint32_t& at = material_at[position_of[mesh.indices[3 * t + c]]];
            if (at == kUnused)
                at = m;
            else if (at != m)
                at = kShared;
        }
    }
    for (size_t v = 0; v < locked.size(); ++v)
        if (material_at[position_of[v]] == kShared) locked[v] = true;
    return locked;
}

}  // namespace

std::vector<BrickLevel> MakeBrickLevels(const BrickMesh& full, const LevelOptions& options,
                                        const Bounds3f* cell) {
    std::vector<BrickLevel> levels;
    // Each level is simplified from the one before, by reference: no reallocation.
    levels.reserve(options.relative_errors.size());
    if (full.TriangleCount() < kMinLevelSourceTriangles || full.VertexCount() == 0) return levels;

    Bounds3f box;
    for (const Vec3f& p : full.positions) box.Extend(p);
    const double extent = double(Length(box.Diagonal()));
    using BorderLock = LevelOptions::BorderLock;
    const bool selective = options.border_lock == BorderLock::kCutAndMaterials && cell != nullptr;
    const bool lock_every_border = options.border_lock != BorderLock::kNone && !selective;
    Scratch scratch;
    const BrickMesh* source = &full;
    float source_error = 0;  // the error `source` already carries
    for (const double relative : options.relative_errors) {
        if (!(relative > 0 && relative < 1)) break;
        // Each step simplifies from the level before, whose error counts toward this one's.
        const float step_target = float(relative * extent) - source_error;
        if (!(step_target > 0)) break;
        scratch.local_of.assign(source->VertexCount(), kUnused);
        if (selective) scratch.locked = LockedVertices(*source, *cell);
        BrickLevel level;
        float step_error = 0;
        for (const Submesh& sub : SplitByMaterial(*source)) {
            step_error = std::max(step_error,
                                  SimplifySubmesh(*source, sub, step_target, lock_every_border,
                                                  options.max_area_change, scratch, &level.mesh));
        }
        const size_t triangles = level.mesh.TriangleCount();
        if (triangles == 0) break;
        if (double(triangles) > options.max_kept_fraction * double(source->TriangleCount()))
            continue;  // hardly coarser: the next error, from the same source

        CompactVertices(*source, options.keep_normals, &level.mesh);
        // A level simplified from the one before differs from the full mesh by at most both
        // errors (triangle inequality): conservative, and larger than the previous level's. A
        // flat region simplifies without error; the next float keeps the errors increasing.
        level.error = source_error + kErrorSafety * step_error;
        if (!levels.empty() && !(level.error > source_error))
            level.error = std::nextafter(source_error, std::numeric_limits<float>::infinity());
        levels.push_back(std::move(level));
        source = &levels.back().mesh;
        source_error = levels.back().error;
    }
    return levels;
}

}  // namespace nave::store
