#include "store/face_shading.h"

#include <cmath>
#include <numbers>
#include <numeric>

#include "src/core/key_table.h"

namespace nave::store::codec {
namespace {

constexpr uint32_t kNone = 0xffffffffu;

/// Disjoint sets of input vertices (path halving, union by index): the patches of smooth faces.
class VertexSets {
  public:
    explicit VertexSets(size_t vertex_count) : parent_(vertex_count) {
        std::iota(parent_.begin(), parent_.end(), 0u);
    }
    uint32_t Find(uint32_t v) {
        while (parent_[v] != v) v = parent_[v] = parent_[parent_[v]];
        return v;
    }
    void Unite(uint32_t a, uint32_t b) {
        a = Find(a);
        b = Find(b);
        if (a != b) parent_[std::max(a, b)] = std::min(a, b);
    }

  private:
    std::vector<uint32_t> parent_;
};

bool IsFlat(const BrickMesh& mesh, const uint32_t* corner, const std::vector<Vec3i>& grid_point) {
    const Vec3d ng =
        GridNormal(grid_point[corner[0]], grid_point[corner[1]], grid_point[corner[2]]);
    const double ng_len = Length(ng);
    if (!(ng_len > 0)) return false;
    for (int c = 0; c < 3; ++c) {
        const Vec3d n(mesh.normals[corner[c]]);
        // Unsigned: the renderer orients the geometric normal by the winding.
        if (std::fabs(Dot(ng, n)) < kFlatCosine * ng_len * Length(n)) return false;
    }
    return true;
}

}  // namespace

std::array<Vec3d, 3> AngleWeightedNormals(const Vec3i& a, const Vec3i& b, const Vec3i& c) {
    const Vec3i p[3] = {a, b, c};
    const Vec3d n = GridNormal(a, b, c);
    const double length = Length(n);
    std::array<Vec3d, 3> out{};
    if (!(length > 0)) return out;
    for (int k = 0; k < 3; ++k) {
        const Vec3i &o = p[k], &u = p[(k + 1) % 3], &v = p[(k + 2) % 3];
        const Vec3d e1(double(u.x) - o.x, double(u.y) - o.y, double(u.z) - o.z);
        const Vec3d e2(double(v.x) - o.x, double(v.y) - o.y, double(v.z) - o.z);
        // |e1 x e2| = 2 * area for every corner: the same as `length`.
        const double angle = std::atan2(length, Dot(e1, e2));
        out[k] = n * (angle / length);
    }
    return out;
}

FaceShading ChooseFaceShading(const BrickMesh& mesh, const std::vector<uint32_t>& faces,
                              const std::vector<Vec3i>& grid_point,
                              const std::vector<uint32_t>& position_id,
                              const Bounds3i& complete_within, double max_error_deg) {
    const size_t n = faces.size();
    FaceShading out;
    out.shading.assign(n, kShadingFlat);
    out.group.assign(n, 0);
    out.flat_count = n;
    if (!mesh.HasNormals()) return out;
    auto corners = [&](size_t k) { return &mesh.indices[3 * size_t(faces[k])]; };

    // 1. Flat faces; the others are candidates for derived normals if the brick holds every face
    // around their corners.
    auto complete = [&](const Vec3i& g) {
        return g.x > complete_within.min.x && g.y > complete_within.min.y &&
               g.z > complete_within.min.z && g.x < complete_within.max.x &&
               g.y < complete_within.max.y && g.z < complete_within.max.z;
    };
    for (size_t k = 0; k < n; ++k) {
        const uint32_t* c = corners(k);
        if (IsFlat(mesh, c, grid_point)) continue;
        --out.flat_count;
        const bool derivable = max_error_deg > 0 && complete(grid_point[c[0]]) &&
                               complete(grid_point[c[1]]) && complete(grid_point[c[2]]);
        out.shading[k] = derivable ? kShadingDerived : kShadingStored;
    }
    if (out.flat_count == n) return out;

    // 2. Patches: faces joined through shared input vertices, numbered in first-seen order.
    VertexSets sets(mesh.VertexCount());
    for (size_t k = 0; k < n; ++k) {
        if (out.shading[k] == kShadingFlat) continue;
        const uint32_t* c = corners(k);
        sets.Unite(c[0], c[1]);
        sets.Unite(c[0], c[2]);
    }
    std::vector<uint32_t> patch_of_root(mesh.VertexCount(), kNone), face_patch(n, kNone);
    uint32_t patch_count = 0;
    for (size_t k = 0; k < n; ++k) {
        if (out.shading[k] == kShadingFlat) continue;
        uint32_t& patch = patch_of_root[sets.Find(corners(k)[0])];
        if (patch == kNone) patch = patch_count++;
        face_patch[k] = patch;
    }
    // Faces by patch (a counting sort).
    std::vector<uint32_t> patch_begin(patch_count + 1, 0), patch_faces(n - out.flat_count);
    for (size_t k = 0; k < n; ++k) {
        if (face_patch[k] != kNone) ++patch_begin[face_patch[k] + 1];
    }
    std::partial_sum(patch_begin.begin(), patch_begin.end(), patch_begin.begin());
    {
        std::vector<uint32_t> next(patch_begin.begin(), patch_begin.end() - 1);
        for (size_t k = 0; k < n; ++k) {
            if (face_patch[k] != kNone) patch_faces[next[face_patch[k]]++] = uint32_t(k);
        }
    }

    // 3. Sites: (grid point, material) of the corners of faces that are not flat.
    struct SiteKey {
        uint32_t position, material;
    };
    KeyTable<SiteKey> sites;
    sites.Reset(3 * (n - out.flat_count));
    std::vector<uint32_t> corner_site(3 * n, kNone);
    for (size_t k = 0; k < n; ++k) {
        if (out.shading[k] == kShadingFlat) continue;
        const uint32_t* c = corners(k);
        for (int j = 0; j < 3; ++j) {
            corner_site[3 * k + j] = sites.Insert({position_id[c[j]], mesh.material_ids[faces[k]]});
        }
    }

    // 4. Smoothing groups, greedily: each patch takes the lowest group that no patch met before
    // uses at any of its sites. A patch left without one stores its normals apart.
    std::vector<uint8_t> site_groups(sites.size(), 0);  // bit g: group g is used there
    for (uint32_t p = 0; p < patch_count; ++p) {
        uint8_t used = 0;
        for (uint32_t i = patch_begin[p]; i < patch_begin[p + 1]; ++i) {
            for (int j = 0; j < 3; ++j)
                used |= site_groups[corner_site[3 * size_t(patch_faces[i]) + j]];
        }
        int group = 0;
        while (group < kSmoothingGroups && (used >> group & 1) != 0) ++group;
        for (uint32_t i = patch_begin[p]; i < patch_begin[p + 1]; ++i) {
            const uint32_t k = patch_faces[i];
            if (group == kSmoothingGroups) {
                out.shading[k] = kShadingStoredApart;
                continue;
            }
            out.group[k] = uint8_t(group);
            for (int j = 0; j < 3; ++j)
                site_groups[corner_site[3 * size_t(k) + j]] |= uint8_t(1u << group);
        }
    }

    // 5. Derived normals per (site, group), then the check of every candidate.
    const double min_cosine = std::cos(max_error_deg * (std::numbers::pi / 180));
    std::vector<Vec3d> sum(sites.size() * kSmoothingGroups, Vec3d(0, 0, 0));
    auto slot = [&](size_t k, int j) {
        return corner_site[3 * k + j] * kSmoothingGroups + out.group[k];
    };
    for (size_t k = 0; k < n; ++k) {
        if (out.shading[k] != kShadingDerived && out.shading[k] != kShadingStored) continue;
        const uint32_t* c = corners(k);
        const auto w = AngleWeightedNormals(grid_point[c[0]], grid_point[c[1]], grid_point[c[2]]);
        for (int j = 0; j < 3; ++j) sum[slot(k, j)] += w[j];
    }
    for (size_t k = 0; k < n; ++k) {
        if (out.shading[k] != kShadingDerived) {
            out.stored_count += out.shading[k] != kShadingFlat;
            continue;
        }
        const uint32_t* c = corners(k);
        for (int j = 0; j < 3; ++j) {
            const Vec3d& derived = sum[slot(k, j)];
            const Vec3d given(mesh.normals[c[j]]);
            // Signed: a derived normal faces the winding's front, as the given ones should.
            const double length = Length(derived) * Length(given);
            if (!(length > 0) || Dot(derived, given) < min_cosine * length) {
                out.shading[k] = kShadingStored;
                ++out.stored_count;
                break;
            }
        }
    }
    return out;
}

}  // namespace nave::store::codec
