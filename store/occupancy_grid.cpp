#include "store/occupancy_grid.h"

#include <lz4.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace nave::store {
namespace {

constexpr int kN = OccupancyGrid::kResolution;

/// How far each triangle's box is grown, in voxels: far beyond the rounding of float hits and of
/// the double arithmetic below, so that a triangle touching a voxel face marks the voxels on both
/// sides and a ray grazing it meets a marked voxel.
constexpr double kGrowVoxels = 1e-3;

/// Whether triangle (a, b, c) overlaps the box centred at the origin with half-extents h: the
/// separating axis theorem over the box's three axes (done by the caller's voxel range), the
/// triangle's normal and the nine products of an edge with a box axis (Akenine-Möller 2001,
/// "Fast 3D triangle-box overlap testing").
bool TriangleOverlapsBox(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& h) {
    const Vec3d v[3] = {a, b, c};
    const Vec3d e[3] = {b - a, c - b, a - c};
    for (int i = 0; i < 3; ++i) {      // edge
        for (int k = 0; k < 3; ++k) {  // box axis: the axis e[i] x unit(k)
            Vec3d axis(0, 0, 0);
            const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
            axis[k1] = e[i][k2];
            axis[k2] = -e[i][k1];
            double lo = INFINITY, hi = -INFINITY;
            for (const Vec3d& p : v) {
                const double s = Dot(p, axis);
                lo = std::min(lo, s);
                hi = std::max(hi, s);
            }
            const double r = h[k1] * std::abs(axis[k1]) + h[k2] * std::abs(axis[k2]);
            if (lo > r || hi < -r) return false;
        }
    }
    const Vec3d n = Cross(e[0], e[1]);
    const double r = h.x * std::abs(n.x) + h.y * std::abs(n.y) + h.z * std::abs(n.z);
    const double s = Dot(n, a);
    return !(s > r || s < -r);
}

}  // namespace

OccupancyGrid OccupancyGrid::Of(std::span<const Vec3f> positions,
                                std::span<const uint32_t> indices) {
    OccupancyGrid g;
    g.bits_.assign(size_t(kN) * kN * kN / 64, 0);
    if (indices.size() < 3 || positions.empty()) return g;
    Bounds3d box;
    for (const Vec3f& p : positions) box.Extend(Vec3d(p));
    // A margin around the box, so that a flat brick (one wall) still has voxels of some depth.
    const Vec3d diagonal = box.Diagonal();
    const double pad = 1e-4 * std::max({diagonal.x, diagonal.y, diagonal.z, 1e-3});
    g.origin_ = box.min - Vec3d(pad, pad, pad);
    for (int a = 0; a < 3; ++a) g.voxel_size_[a] = (diagonal[a] + 2 * pad) / kN;
    g.empty_box_ = false;
    const Vec3d half = g.voxel_size_ * (0.5 + kGrowVoxels);
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
        const Vec3d v[3] = {Vec3d(positions[indices[i]]), Vec3d(positions[indices[i + 1]]),
                            Vec3d(positions[indices[i + 2]])};
        Bounds3d t;
        for (const Vec3d& p : v) t.Extend(p);
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::clamp(
                int(std::floor((t.min[a] - g.origin_[a]) / g.voxel_size_[a] - kGrowVoxels)), 0,
                kN - 1);
            hi[a] = std::clamp(
                int(std::floor((t.max[a] - g.origin_[a]) / g.voxel_size_[a] + kGrowVoxels)), 0,
                kN - 1);
        }
        // A triangle within one or two voxels along every axis marks its box; a larger one (a
        // vault's web, a slanted roof) only the voxels its plane crosses.
        const bool small = hi[0] - lo[0] < 2 && hi[1] - lo[1] < 2 && hi[2] - lo[2] < 2;
        for (int z = lo[2]; z <= hi[2]; ++z) {
            for (int y = lo[1]; y <= hi[1]; ++y) {
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    if (!small) {
                        const Vec3d centre = g.origin_ + Vec3d(g.voxel_size_.x * (x + 0.5),
                                                               g.voxel_size_.y * (y + 0.5),
                                                               g.voxel_size_.z * (z + 0.5));
                        if (!TriangleOverlapsBox(v[0] - centre, v[1] - centre, v[2] - centre, half))
                            continue;
                    }
                    const uint32_t bit = uint32_t((z * kN + y) * kN + x);
                    g.bits_[bit >> 6] |= uint64_t(1) << (bit & 63);
                }
            }
        }
    }
    return g;
}

bool OccupancyGrid::SegmentEmpty(const Vec3f& of, const Vec3f& df, float t0, float t1) const {
    if (empty_box_) return true;
    if (!(t0 <= t1)) return false;
    const Vec3d o(of), d(df);
    // The segment clipped to the grid's box (slabs, Kay & Kajiya 1986).
    double lo = t0, hi = t1;
    for (int a = 0; a < 3; ++a) {
        const double min = origin_[a], max = origin_[a] + kN * voxel_size_[a];
        if (d[a] == 0) {
            if (o[a] < min || o[a] > max) return true;
            continue;
        }
        double near = (min - o[a]) / d[a], far = (max - o[a]) / d[a];
        if (near > far) std::swap(near, far);
        lo = std::max(lo, near);
        hi = std::min(hi, far);
        if (lo > hi) return true;
    }
    if (!std::isfinite(lo) || !std::isfinite(hi)) return false;
    // Voxel walk from where the segment enters (Amanatides & Woo 1987, "A fast voxel traversal
    // algorithm for ray tracing").
    int cell[3], step[3];
    double t_next[3], t_delta[3];
    for (int a = 0; a < 3; ++a) {
        const double p = o[a] + d[a] * lo;
        cell[a] = std::clamp(int(std::floor((p - origin_[a]) / voxel_size_[a])), 0, kN - 1);
        if (d[a] > 0) {
            step[a] = 1;
            t_next[a] = (origin_[a] + (cell[a] + 1) * voxel_size_[a] - o[a]) / d[a];
            t_delta[a] = voxel_size_[a] / d[a];
        } else if (d[a] < 0) {
            step[a] = -1;
            t_next[a] = (origin_[a] + cell[a] * voxel_size_[a] - o[a]) / d[a];
            t_delta[a] = -voxel_size_[a] / d[a];
        } else {
            step[a] = 0;
            t_next[a] = INFINITY;
            t_delta[a] = INFINITY;
        }
    }
    for (;;) {
        if (Marked(cell[0], cell[1], cell[2])) return false;
        const int a = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2)
                                            : (t_next[1] < t_next[2] ? 1 : 2);
        if (t_next[a] > hi) return true;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] >= kN) return true;
        t_next[a] += t_delta[a];
    }
}

namespace {

/// Bytes before the LZ4 block of an occupancy section: u32 resolution, u32 bytes of the bits once
/// decompressed, the box's lower corner and voxel size (3 + 3 doubles).
constexpr size_t kSectionHeadBytes = 8 + 6 * sizeof(double);

}  // namespace

std::string OccupancyGrid::Encode() const {
    if (empty_box_) return std::string();
    const size_t raw = bits_.size() * sizeof(uint64_t);
    std::string out(kSectionHeadBytes + size_t(LZ4_compressBound(int(raw))), '\0');
    const uint32_t head[2] = {uint32_t(kN), uint32_t(raw)};
    const double box[6] = {origin_.x,     origin_.y,     origin_.z,
                           voxel_size_.x, voxel_size_.y, voxel_size_.z};
    std::memcpy(out.data(), head, sizeof head);
    std::memcpy(out.data() + sizeof head, box, sizeof box);
    const int n = LZ4_compress_default(reinterpret_cast<const char*>(bits_.data()),
                                       out.data() + kSectionHeadBytes, int(raw),
                                       int(out.size() - kSectionHeadBytes));
    NAVE_CHECK_GT(n, 0) << "LZ4 failed on an occupancy grid";
    out.resize(kSectionHeadBytes + size_t(n));
    return out;
}

StatusOr<OccupancyGrid> OccupancyGrid::Decode(std::string_view bytes, const std::string& what) {
    if (bytes.size() < kSectionHeadBytes)
        return DataLossError("{}: {} bytes, fewer than an occupancy grid's {}-byte head", what,
                             bytes.size(), kSectionHeadBytes);
    uint32_t head[2];
    double box[6];
    std::memcpy(head, bytes.data(), sizeof head);
    std::memcpy(box, bytes.data() + sizeof head, sizeof box);
    const uint32_t raw = uint32_t(kN) * kN * kN / 8;
    if (head[0] != uint32_t(kN) || head[1] != raw)
        return DataLossError("{}: a grid of {} voxels a side and {} bytes (expected {} and {})",
                             what, head[0], head[1], kN, raw);
    for (int a = 0; a < 6; ++a)
        if (!std::isfinite(box[a]) || (a >= 3 && !(box[a] > 0)))
            return DataLossError("{}: its box ({}, {}, {}) + voxels of ({}, {}, {}) is not one",
                                 what, box[0], box[1], box[2], box[3], box[4], box[5]);
    OccupancyGrid g;
    g.bits_.assign(raw / sizeof(uint64_t), 0);
    const int n = LZ4_decompress_safe(bytes.data() + kSectionHeadBytes,
                                      reinterpret_cast<char*>(g.bits_.data()),
                                      int(bytes.size() - kSectionHeadBytes), int(raw));
    if (n != int(raw))
        return DataLossError("{}: its bits do not decompress to the grid's {} bytes", what, raw);
    g.origin_ = Vec3d(box[0], box[1], box[2]);
    g.voxel_size_ = Vec3d(box[3], box[4], box[5]);
    g.empty_box_ = false;
    return g;
}

double OccupancyGrid::MarkedFraction() const {
    uint64_t marked = 0;
    for (uint64_t w : bits_) marked += uint64_t(__builtin_popcountll(w));
    return double(marked) / double(uint64_t(kN) * kN * kN);
}

}  // namespace nave::store
