#include "store/brick_codec.h"

#include <draco/compression/decode.h>
#include <draco/compression/expert_encode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/encoder_buffer.h>
#include <draco/mesh/mesh.h>
#include <fmt/ostream.h>
#include <lz4.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "src/core/key_table.h"
#include "store/face_shading.h"
#include "store/occupancy_grid.h"

namespace nave::store::codec {
namespace {

// The position is an integer attribute without Draco quantization: Draco predicts and entropy-codes
// integers losslessly, so decoding gives back exactly the grid indices (docs/store-format.md,
// "Grid").
constexpr draco::GeometryAttribute::Type kPositionType = draco::GeometryAttribute::POSITION;
constexpr draco::GeometryAttribute::Type kNormalType = draco::GeometryAttribute::NORMAL;
constexpr draco::GeometryAttribute::Type kUvType = draco::GeometryAttribute::TEX_COORD;
// Material ids ride as a per-point integer attribute whose value is equal on the three corners of
// every face. Draco keeps attribute values attached to corners through its edgebreaker face
// reordering, so a face's material is the value at any of its corners (Draco splits a vertex shared
// by two materials).
constexpr draco::GeometryAttribute::Type kMaterialType = draco::GeometryAttribute::GENERIC;
Vec3f Normalized(const Vec3f& n) {
    const double len = std::sqrt(double(n.x) * n.x + double(n.y) * n.y + double(n.z) * n.z);
    return {float(n.x / len), float(n.y / len), float(n.z / len)};
}

std::unique_ptr<draco::PointAttribute> NewAttribute(draco::GeometryAttribute::Type type,
                                                    int components, draco::DataType data_type,
                                                    size_t values) {
    auto att = std::make_unique<draco::PointAttribute>();
    att->Init(type, int8_t(components), data_type, false, values);
    return att;
}

/// Direct access to a decoded attribute's values by point: the point's value index (identity or
/// explicit mapping), then the value's bytes in the attribute's buffer.
class PlainAttribute {
  public:
    explicit PlainAttribute(const draco::PointAttribute& att) : att_(att) {}
    template <typename T>
    const T* Value(uint32_t point) const {
        const draco::AttributeValueIndex v = att_.mapped_index(draco::PointIndex(point));
        return reinterpret_cast<const T*>(att_.GetAddress(v));
    }

  private:
    const draco::PointAttribute& att_;
};

/// Whether point a's grid position is lexicographically below point b's.
bool LessPosition(const PlainAttribute& positions, uint32_t a, uint32_t b) {
    const int32_t* pa = positions.Value<int32_t>(a);
    const int32_t* pb = positions.Value<int32_t>(b);
    return std::lexicographical_compare(pa, pa + 3, pb, pb + 3);
}

/// Copies N float components per point into `out`; float attributes (what Draco gives back for
/// quantized normals and uvs) are copied as they are, other types converted.
template <int N>
Status CopyFloatValues(const draco::PointAttribute& att, uint32_t point_count,
                       const std::string& what, const char* name, float* out) {
    if (att.data_type() == draco::DT_FLOAT32) {
        const PlainAttribute plain(att);
        for (uint32_t p = 0; p < point_count; ++p) {
            std::memcpy(out + size_t(N) * p, plain.Value<float>(p), N * sizeof(float));
        }
        return Status::Ok();
    }
    for (uint32_t p = 0; p < point_count; ++p) {
        if (!att.ConvertValue<float, N>(att.mapped_index(draco::PointIndex(p)),
                                        out + size_t(N) * p)) {
            return DataLossError("{}: cannot read the {} of vertex {}", what, name, p);
        }
    }
    return Status::Ok();
}

/// Sets the normals of a decoded brick's derived faces (face_shading.h): per point, the
/// angle-weighted normals of its faces that count (stored or derived), then added up per (grid
/// point, material, smoothing group) as the encoder did (ChooseFaceShading), not per Draco point,
/// since Draco splits a point at a non-manifold vertex; normalised into the derived faces' points.
void DeriveNormals(const draco::Mesh& dm, const PlainAttribute& positions,
                   const PlainAttribute& values, std::vector<Vec3f>* normals) {
    enum : uint8_t { kNotCounted = 0, kCounted = 1, kDerived = 2 };
    const uint32_t point_count = dm.num_points();
    std::vector<uint8_t> role(point_count, kNotCounted);
    std::vector<Vec3f> point_sum(point_count, Vec3f(0, 0, 0));
    auto grid_point = [&](uint32_t p) {
        const int32_t* v = positions.Value<int32_t>(p);
        return Vec3i(v[0], v[1], v[2]);
    };
    for (uint32_t f = 0; f < dm.num_faces(); ++f) {
        const draco::Mesh::Face& face = dm.face(draco::FaceIndex(f));
        const int shading = *values.Value<int32_t>(face[0].value()) & 3;
        if (shading != kShadingDerived && shading != kShadingStored) continue;
        const uint32_t p[3] = {face[0].value(), face[1].value(), face[2].value()};
        const auto w = AngleWeightedNormals(grid_point(p[0]), grid_point(p[1]), grid_point(p[2]));
        for (int c = 0; c < 3; ++c) {
            point_sum[p[c]] += Vec3f(w[c]);
            role[p[c]] = shading == kShadingDerived ? kDerived : kCounted;
        }
    }
    struct SiteKey {
        int32_t x, y, z, material_and_group;
    };
    KeyTable<SiteKey> sites;
    sites.Reset(point_count);
    std::vector<uint32_t> site_of_point(point_count);
    std::vector<Vec3f> site_sum;
    for (uint32_t p = 0; p < point_count; ++p) {
        if (role[p] == kNotCounted) continue;
        const Vec3i g = grid_point(p);
        bool inserted = false;
        const uint32_t site =
            sites.Insert({g.x, g.y, g.z, *values.Value<int32_t>(p) >> 2}, &inserted);
        if (inserted) site_sum.emplace_back(0, 0, 0);
        site_sum[site] += point_sum[p];
        site_of_point[p] = site;
    }
    for (uint32_t p = 0; p < point_count; ++p) {
        if (role[p] != kDerived) continue;
        const Vec3f& n = site_sum[site_of_point[p]];
        const float length = Length(n);
        // Zero only if the faces cancel, which the encoder rules out: fall back to the geometric
        // normal rather than divide by zero.
        (*normals)[p] = length > 0 ? n / length : Vec3f(0, 0, 0);
    }
}

}  // namespace

StatusOr<EncodedMesh> EncodeMeshSection(const BrickMesh& mesh, const GlobalGrid& grid,
                                        const EncodeOptions& options,
                                        const Bounds3f& complete_within, uint32_t grid_shift) {
    if (!(grid.step > 0) || !std::isfinite(grid.step) || !IsFinite(grid.origin)) {
        return InvalidArgumentError(
            "invalid grid: origin {}, step {} (the step must be finite and > 0)",
            fmt::streamed(grid.origin), grid.step);
    }
    if (options.draco_speed < 0 || options.draco_speed > 10) {
        return InvalidArgumentError("draco speed {} out of range [0, 10]", options.draco_speed);
    }
    if (!(options.derived_normal_error_deg >= 0 && options.derived_normal_error_deg <= 10)) {
        return InvalidArgumentError("derived normal error {} degrees out of range [0, 10]",
                                    options.derived_normal_error_deg);
    }
    if (options.normal_bits < 2 || options.normal_bits > 30 || options.uv_bits < 1 ||
        options.uv_bits > 30) {
        return InvalidArgumentError(
            "normal bits {} (expected 2..30) or uv bits {} (expected 1..30) out of range",
            options.normal_bits, options.uv_bits);
    }
    if (grid_shift > kMaxMeshGridShift) {
        return InvalidArgumentError("grid shift {} out of range [0, {}]", grid_shift,
                                    kMaxMeshGridShift);
    }
    const size_t vertex_count = mesh.VertexCount();
    const size_t triangle_count = mesh.TriangleCount();
    // With a shift, every 2^shift-th grid point (indices stay the grid's: a multiple of 2^shift).
    const int64_t shift_scale = int64_t(1) << grid_shift;
    GlobalGrid snap_grid = grid;
    snap_grid.step = grid.step * double(shift_scale);

    // 1. Snap every position to the grid.
    constexpr double kLimit = double(std::numeric_limits<int32_t>::max() - 1);
    std::vector<Vec3i> q(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) {
        const Vec3f& p = mesh.positions[v];
        for (int a = 0; a < 3; ++a) {
            const double t = (double(p[a]) - grid.origin[a]) / grid.step;
            if (!(std::fabs(t) < kLimit)) {
                return InvalidArgumentError(
                    "vertex {} at {} lies outside the grid's int32 range (origin {}, step {}): "
                    "choose a larger "
                    "step or an origin nearer the model",
                    v, fmt::streamed(p), fmt::streamed(grid.origin), grid.step);
            }
        }
        q[v] = grid.Quantize(p);
        if (grid_shift > 0) {
            const Vec3i c = snap_grid.Quantize(p);
            for (int a = 0; a < 3; ++a) {
                const int64_t index = int64_t(c[a]) * shift_scale;
                if (!(std::llabs(index) < int64_t(kLimit))) {
                    return InvalidArgumentError(
                        "vertex {} at {} lies outside the grid's int32 range once snapped to "
                        "every {}th grid point",
                        v, fmt::streamed(p), shift_scale);
                }
                q[v][a] = int32_t(index);
            }
        }
    }

    // 2. One Draco position value per distinct grid point, so that vertices the input split (for
    // normal or UV seams) stay connected for edgebreaker.
    // Sorted by value with the vertex beside it: comparisons read neighbouring memory, not q[] at
    // random (the indirect sort was 8 % of preprocessing).
    struct GridVertex {
        Vec3i q;
        uint32_t vertex;
    };
    std::vector<GridVertex> order(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) order[v] = {q[v], uint32_t(v)};
    std::sort(order.begin(), order.end(), [](const GridVertex& a, const GridVertex& b) {
        if (a.q.x != b.q.x) return a.q.x < b.q.x;
        if (a.q.y != b.q.y) return a.q.y < b.q.y;
        if (a.q.z != b.q.z) return a.q.z < b.q.z;
        return a.vertex < b.vertex;
    });
    std::vector<uint32_t> position_value(vertex_count);
    std::vector<Vec3i> unique_positions;
    for (size_t i = 0; i < vertex_count; ++i) {
        if (i == 0 || order[i].q != order[i - 1].q) unique_positions.push_back(order[i].q);
        position_value[order[i].vertex] = uint32_t(unique_positions.size() - 1);
    }

    // 3. Drop triangles that collapse on the grid (two corners on one grid point): they have no
    // area, no ray can hit them, and Draco's connectivity coder does not keep them.
    EncodedMesh out;
    out.has_normals = mesh.HasNormals();
    out.has_uvs = mesh.HasUvs();
    std::vector<uint32_t> kept;
    kept.reserve(triangle_count);
    for (size_t t = 0; t < triangle_count; ++t) {
        const uint32_t a = position_value[mesh.indices[3 * t]],
                       b = position_value[mesh.indices[3 * t + 1]],
                       c = position_value[mesh.indices[3 * t + 2]];
        if (a == b || b == c || a == c) continue;
        kept.push_back(uint32_t(t));
        out.max_material_id = std::max(out.max_material_id, mesh.material_ids[t]);
    }
    out.dropped_triangle_count = triangle_count - kept.size();
    if (out.max_material_id > kMaxMaterialId) {
        return InvalidArgumentError("material id {} exceeds the largest storable id {}",
                                    out.max_material_id, kMaxMaterialId);
    }

    // Where the kept triangles lie, as they will decode (each corner dequantized from its grid
    // point, as the reader does): the brick's occupancy grid (format 3.4), for its own grid only.
    if (options.occupancy && grid_shift == 0 && !kept.empty()) {
        std::vector<Vec3f> corners(3 * kept.size());
        std::vector<uint32_t> corner_index(3 * kept.size());
        for (size_t k = 0; k < kept.size(); ++k)
            for (int c = 0; c < 3; ++c) {
                corners[3 * k + c] = grid.Dequantize(q[mesh.indices[3 * kept[k] + c]]);
                corner_index[3 * k + c] = uint32_t(3 * k + c);
            }
        out.occupancy = OccupancyGrid::Of(corners, corner_index).Encode();
    }

    // 4. Shading (docs/store-format.md, "Shading"; face_shading.h): faces whose normals are their
    // geometric normal (flat) or can be recomputed from the positions (derived) store none, and
    // their corners are joined by (grid point, material value, uv) rather than by input vertex, so
    // surfaces whose inputs split every corner by normal share their vertices again: fewer points
    // to decode, store and keep resident.
    // In grid steps, shrunk by two: a vertex's snapped position may lie half a step outside the
    // box its unsnapped one was tested against, and the box's float bounds round too.
    Bounds3i complete_cell;
    for (int a = 0; a < 3; ++a) {
        auto to_grid = [&](float x, double toward) {
            const double t =
                std::clamp((double(x) - grid.origin[a]) / grid.step, -kLimit + 4, kLimit - 4);
            return int32_t(std::lround(t + toward));
        };
        complete_cell.min[a] = to_grid(complete_within.min[a], 2.0);
        complete_cell.max[a] = to_grid(complete_within.max[a], -2.0);
    }
    const FaceShading shading = ChooseFaceShading(mesh, kept, q, position_value, complete_cell,
                                                  options.derived_normal_error_deg);
    const size_t stored_count = shading.stored_count;
    // The decoded mesh has normals when some face is not flat; the material attribute then holds
    // each face's shading and smoothing group.
    out.has_normals = mesh.HasNormals() && shading.flat_count < kept.size();
    auto material_value = [&](size_t k) {
        const uint32_t material = mesh.material_ids[kept[k]];
        return out.has_normals
                   ? material << 4 | uint32_t(shading.group[k]) << 2 | shading.shading[k]
                   : material;
    };

    // 5. Points: a stored face's corner is one point per (input vertex, material value) pair (its
    // normal and uv are the vertex's); a flat or derived face's corner is one point per (grid
    // point, material value, uv). A point is never shared by faces of two shadings (their material
    // values differ), so decoding knows each point's normal.
    constexpr uint32_t kUnset = 0xffffffffu;
    std::vector<uint32_t> point_of_vertex(stored_count > 0 ? vertex_count : 0, kUnset);
    std::vector<uint32_t> value_of_vertex(stored_count > 0 ? vertex_count : 0, 0);
    std::unordered_map<uint64_t, uint32_t> extra_points;
    struct CornerKey {
        uint32_t position, value, uv[2];
    };
    KeyTable<CornerKey> corner_keys;
    corner_keys.Reset(3 * (kept.size() - stored_count));
    std::vector<uint32_t> point_of_key;
    std::vector<uint32_t> point_vertex, point_value;
    std::vector<uint8_t> point_shading;
    std::vector<uint32_t> faces(3 * kept.size());
    Vec3i lo{std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::max(),
             std::numeric_limits<int32_t>::max()};
    Vec3i hi{std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::min(),
             std::numeric_limits<int32_t>::min()};
    auto new_point = [&](uint32_t v, uint32_t value, uint8_t face_shading) {
        point_vertex.push_back(v);
        point_value.push_back(value);
        point_shading.push_back(face_shading);
        lo = Min(lo, q[v]);
        hi = Max(hi, q[v]);
        return uint32_t(point_vertex.size() - 1);
    };
    for (size_t k = 0; k < kept.size(); ++k) {
        const uint32_t t = kept[k];
        const uint32_t value = material_value(k);
        const uint8_t face_shading = shading.shading[k];
        const bool stored = StoresNormals(face_shading);
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = mesh.indices[3 * size_t(t) + c];
            uint32_t point;
            if (!stored) {
                CornerKey key{position_value[v], value, {0, 0}};
                if (out.has_uvs) std::memcpy(key.uv, mesh.uvs[v].data(), sizeof(key.uv));
                bool inserted = false;
                const uint32_t id = corner_keys.Insert(key, &inserted);
                if (inserted) point_of_key.push_back(new_point(v, value, face_shading));
                point = point_of_key[id];
            } else if (point_of_vertex[v] == kUnset) {
                point = point_of_vertex[v] = new_point(v, value, face_shading);
                value_of_vertex[v] = value;
            } else if (value_of_vertex[v] == value) {
                point = point_of_vertex[v];
            } else {
                const uint64_t key = (uint64_t(v) << 32) | value;
                auto it = extra_points.find(key);
                point = it != extra_points.end()
                            ? it->second
                            : extra_points.emplace(key, new_point(v, value, face_shading))
                                  .first->second;
            }
            faces[3 * k + c] = point;
        }
    }
    const size_t point_count = point_vertex.size();

    // 6. Positions are stored relative to the brick's smallest grid point.
    const Vec3i base = point_count > 0 ? lo : Vec3i{0, 0, 0};
    for (int a = 0; a < 3; ++a) {
        if (point_count > 0 && int64_t(hi[a]) - int64_t(lo[a]) >= kMaxBrickSpanSteps) {
            return InvalidArgumentError(
                "the brick spans {} grid steps along axis {}, more than the {} a brick may span: "
                "use a larger "
                "grid step or smaller bricks",
                int64_t(hi[a]) - int64_t(lo[a]), "xyz"[a], kMaxBrickSpanSteps);
        }
    }
    out.bytes.resize(kMeshPrefixBytes);
    const uint32_t flags =
        (out.has_normals ? kMeshFlagShading : 0u) | (grid_shift << kMeshGridShiftBit);
    const int32_t prefix[4] = {base.x, base.y, base.z, int32_t(flags)};
    std::memcpy(out.bytes.data(), prefix, kMeshPrefixBytes);

    size_t encoded_points = 0;  // Draco's count, after its own splits: what decoding gives
    if (!kept.empty()) {
        draco::Mesh dm;
        dm.set_num_points(uint32_t(point_count));
        // Positions: distinct grid points, mapped from points.
        auto pos = NewAttribute(kPositionType, 3, draco::DT_INT32, unique_positions.size());
        for (size_t i = 0; i < unique_positions.size(); ++i) {
            const Vec3i& g = unique_positions[i];
            // Exact: every index and the base are multiples of 2^grid_shift.
            const int32_t rel[3] = {(g.x - base.x) >> grid_shift, (g.y - base.y) >> grid_shift,
                                    (g.z - base.z) >> grid_shift};
            pos->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), rel);
        }
        pos->SetExplicitMapping(point_count);
        for (size_t p = 0; p < point_count; ++p) {
            pos->SetPointMapEntry(draco::PointIndex(uint32_t(p)),
                                  draco::AttributeValueIndex(position_value[point_vertex[p]]));
        }
        const int pos_id = dm.AddAttribute(std::move(pos));
        int normal_id = -1, uv_id = -1;
        if (stored_count > 0) {
            auto att = NewAttribute(kNormalType, 3, draco::DT_FLOAT32, point_count);
            for (size_t p = 0; p < point_count; ++p) {
                // Flat and derived faces' points carry one constant (cheap to code); decoding
                // replaces it.
                const Vec3f n = StoresNormals(point_shading[p])
                                    ? Normalized(mesh.normals[point_vertex[p]])
                                    : Vec3f(0, 0, 1);
                const float value[3] = {n.x, n.y, n.z};
                att->SetAttributeValue(draco::AttributeValueIndex(uint32_t(p)), value);
            }
            normal_id = dm.AddAttribute(std::move(att));
        }
        if (out.has_uvs) {
            auto att = NewAttribute(kUvType, 2, draco::DT_FLOAT32, point_count);
            for (size_t p = 0; p < point_count; ++p) {
                att->SetAttributeValue(draco::AttributeValueIndex(uint32_t(p)),
                                       mesh.uvs[point_vertex[p]].data());
            }
            uv_id = dm.AddAttribute(std::move(att));
        }
        {
            auto att = NewAttribute(kMaterialType, 1, draco::DT_INT32, point_count);
            for (size_t p = 0; p < point_count; ++p) {
                const int32_t m = int32_t(point_value[p]);
                att->SetAttributeValue(draco::AttributeValueIndex(uint32_t(p)), &m);
            }
            dm.AddAttribute(std::move(att));
        }
        for (size_t k = 0; k < kept.size(); ++k) {
            dm.AddFace({draco::PointIndex(faces[3 * k]), draco::PointIndex(faces[3 * k + 1]),
                        draco::PointIndex(faces[3 * k + 2])});
        }

        draco::ExpertEncoder encoder(dm);
        encoder.SetTrackEncodedProperties(true);
        encoder.SetSpeedOptions(options.draco_speed, options.draco_speed);
        if (options.sequential) encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
        if (normal_id >= 0) encoder.SetAttributeQuantization(normal_id, options.normal_bits);
        if (uv_id >= 0) encoder.SetAttributeQuantization(uv_id, options.uv_bits);
        (void)pos_id;  // positions are integers: no quantization, lossless
        draco::EncoderBuffer buffer;
        const draco::Status status = encoder.EncodeToBuffer(&buffer);
        if (!status.ok()) {
            return InternalError(
                "Draco could not encode a brick of {} triangles and {} vertices: {}", kept.size(),
                point_count, status.error_msg_string());
        }
        out.bytes.append(buffer.data(), buffer.size());
        encoded_points = encoder.num_encoded_points();
    }
    out.triangle_count = kept.size();
    out.vertex_count = encoded_points;
    out.decoded_bytes =
        BrickMesh::BytesFor(out.vertex_count, out.triangle_count, out.has_normals, out.has_uvs);
    // Dequantizing is monotonic per axis: the box of the decoded positions is that of the extremes.
    if (point_count > 0) out.geometry_bounds = Bounds3f(grid.Dequantize(lo), grid.Dequantize(hi));
    if (!options.verify) return out;

    // 7. Decode once (EncodeOptions::verify): the store must never hold a brick that does not
    // decode to what was given.
    NAVE_ASSIGN_OR_RETURN(
        BrickMesh decoded,
        DecodeMeshSection(out.bytes, grid, uint64_t(out.max_material_id) + 1, "encoded brick"));
    if (decoded.TriangleCount() != kept.size() || decoded.VertexCount() != encoded_points) {
        return InternalError(
            "Draco round trip changed the counts: encoded {} triangles and {} points, decoded {} "
            "and {}",
            kept.size(), encoded_points, decoded.TriangleCount(), decoded.VertexCount());
    }
    std::vector<uint32_t> materials_in(kept.size());
    for (size_t k = 0; k < kept.size(); ++k) materials_in[k] = mesh.material_ids[kept[k]];
    std::vector<uint32_t> materials_out = decoded.material_ids;
    std::sort(materials_in.begin(), materials_in.end());
    std::sort(materials_out.begin(), materials_out.end());
    if (materials_in != materials_out) {
        return InternalError("Draco round trip changed the triangles' material ids ({} triangles)",
                             kept.size());
    }
    Bounds3f decoded_bounds;
    for (const Vec3f& p : decoded.positions) decoded_bounds.Extend(p);
    if (!(decoded_bounds == out.geometry_bounds)) {
        return InternalError("Draco round trip moved the brick's bounds: encoded {}, decoded {}",
                             fmt::streamed(out.geometry_bounds), fmt::streamed(decoded_bounds));
    }
    out.decoded = std::move(decoded);
    return out;
}

StatusOr<BrickMesh> DecodeMeshSection(std::string_view bytes, const GlobalGrid& grid,
                                      uint64_t material_count, const std::string& what) {
    if (bytes.size() < kMeshPrefixBytes) {
        return DataLossError("{}: mesh section of {} bytes is shorter than its {}-byte prefix",
                             what, bytes.size(), kMeshPrefixBytes);
    }
    int32_t prefix[4];
    std::memcpy(prefix, bytes.data(), kMeshPrefixBytes);
    const Vec3i base{prefix[0], prefix[1], prefix[2]};
    const uint32_t flags = uint32_t(prefix[3]);
    constexpr uint32_t kKnownFlags = kMeshFlagFlatFaces | kMeshFlagShading | kMeshGridShiftMask;
    if ((flags & ~kKnownFlags) != 0) {
        return DataLossError(
            "{}: mesh section flags 0x{:x} hold bits this nave does not know (0x{:x})", what, flags,
            flags & ~kKnownFlags);
    }
    const uint32_t grid_shift = (flags & kMeshGridShiftMask) >> kMeshGridShiftBit;
    if (grid_shift > kMaxMeshGridShift) {
        return DataLossError("{}: mesh section grid shift {} out of range [0, {}]", what,
                             grid_shift, kMaxMeshGridShift);
    }
    if ((flags & (kMeshFlagFlatFaces | kMeshFlagShading)) ==
        (kMeshFlagFlatFaces | kMeshFlagShading)) {
        return DataLossError(
            "{}: mesh section flags 0x{:x} mark flat faces in both the 2.0 and the 3.0 way", what,
            flags);
    }
    const bool flat_marked = (flags & kMeshFlagFlatFaces) != 0;
    const bool shading_marked = (flags & kMeshFlagShading) != 0;
    BrickMesh out;
    if (bytes.size() == kMeshPrefixBytes)
        return out;  // a brick whose triangles all collapsed on the grid

    draco::DecoderBuffer buffer;
    buffer.Init(bytes.data() + kMeshPrefixBytes, bytes.size() - kMeshPrefixBytes);
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) {
        return DataLossError("{}: Draco cannot decode the mesh: {}", what,
                             decoded.status().error_msg_string());
    }
    const std::unique_ptr<draco::Mesh> dm = std::move(decoded).value();
    const draco::PointAttribute* pos = dm->GetNamedAttribute(kPositionType);
    const draco::PointAttribute* material = dm->GetNamedAttribute(kMaterialType);
    const draco::PointAttribute* normal = dm->GetNamedAttribute(kNormalType);
    const draco::PointAttribute* uv = dm->GetNamedAttribute(kUvType);
    if (pos == nullptr || pos->data_type() != draco::DT_INT32 || pos->num_components() != 3) {
        return DataLossError("{}: the Draco mesh has no int32 x 3 position attribute", what);
    }
    if (material == nullptr || material->data_type() != draco::DT_INT32 ||
        material->num_components() != 1) {
        return DataLossError("{}: the Draco mesh has no int32 material attribute", what);
    }
    if (normal != nullptr && normal->num_components() != 3) {
        return DataLossError("{}: normals have {} components (expected 3)", what,
                             int(normal->num_components()));
    }
    if (uv != nullptr && uv->num_components() != 2) {
        return DataLossError("{}: texture coordinates have {} components (expected 2)", what,
                             int(uv->num_components()));
    }

    const uint32_t point_count = dm->num_points();
    const uint32_t face_count = dm->num_faces();
    // Exact sizes, so that MemoryBytes() equals BytesFor() and the directory's decoded_bytes.
    out.positions.resize(point_count);
    if (normal != nullptr || shading_marked) out.normals.resize(point_count);
    if (uv != nullptr) out.uvs.resize(point_count);
    out.indices.resize(3 * size_t(face_count));
    out.material_ids.resize(face_count);
    // Values are read straight from the attributes' buffers (the point-to-value mapping, then the
    // value's address): Draco's per-value GetValue/ConvertValue calls cost more than the decode
    // itself on large bricks (bench_brick_load).
    const PlainAttribute positions(*pos);
    for (uint32_t p = 0; p < point_count; ++p) {
        const int32_t* g = positions.Value<int32_t>(p);
        // Summed in 64 bits: the writer keeps every point within int32 of the grid, so a sum beyond
        // it is damage (a prefix or a Draco value), not a position.
        int32_t q[3];
        for (int a = 0; a < 3; ++a) {
            const int64_t sum = int64_t(base[a]) + int64_t(g[a]) * (int64_t(1) << grid_shift);
            if (sum < INT32_MIN || sum > INT32_MAX) {
                return DataLossError(
                    "{}: vertex {} at grid step {} + {} on axis {}: outside the int32 grid", what,
                    p, base[a], g[a], "xyz"[a]);
            }
            q[a] = int32_t(sum);
        }
        out.positions[p] = grid.Dequantize({q[0], q[1], q[2]});
    }
    if (normal != nullptr) {
        NAVE_RETURN_IF_ERROR(CopyFloatValues<3>(*normal, point_count, what, "normal",
                                                reinterpret_cast<float*>(out.normals.data())));
    }
    if (uv != nullptr) {
        NAVE_RETURN_IF_ERROR(CopyFloatValues<2>(*uv, point_count, what, "texture coordinates",
                                                reinterpret_cast<float*>(out.uvs.data())));
    }
    const PlainAttribute materials(*material);
    bool any_derived = false;
    for (uint32_t f = 0; f < face_count; ++f) {
        const draco::Mesh::Face& face = dm->face(draco::FaceIndex(f));
        for (int c = 0; c < 3; ++c) {
            const uint32_t p = face[c].value();
            if (p >= point_count) {
                return DataLossError("{}: triangle {} names vertex {} of {}", what, f, p,
                                     point_count);
            }
            out.indices[3 * size_t(f) + c] = p;
        }
        // Draco's traversal may start a triangle at any corner, and differently in two bricks
        // that hold the same triangle: start every triangle at its lowest grid point, so that
        // Embree sees the same corners in the same order everywhere and a ray gets the same t and
        // barycentrics from every brick (the image must not depend on the decomposition).
        uint32_t* tri = &out.indices[3 * size_t(f)];
        int first = 0;
        for (int c = 1; c < 3; ++c) {
            if (LessPosition(positions, tri[c], tri[first])) first = c;
        }
        std::rotate(tri, tri + first, tri + 3);
        const int32_t value = *materials.Value<int32_t>(face[0].value());
        const int32_t m = shading_marked ? value >> 4 : flat_marked ? value >> 1 : value;
        if (m < 0 || uint64_t(m) >= material_count) {
            return DataLossError("{}: triangle {} has material {} but the store has {} materials",
                                 what, f, m, material_count);
        }
        out.material_ids[f] = uint32_t(m);
        const int shading = shading_marked ? value & 3
                            : flat_marked  ? ((value & 1) != 0 ? kShadingFlat : kShadingStored)
                                           : kShadingStored;
        if (StoresNormals(shading) && shading_marked && normal == nullptr) {
            return DataLossError(
                "{}: triangle {} keeps its normals, but the mesh section stores none", what, f);
        }
        if (shading == kShadingFlat && !out.normals.empty()) {
            // A flat face: zero normals tell the renderer to shade with the geometric normal.
            for (int c = 0; c < 3; ++c) out.normals[tri[c]] = Vec3f(0, 0, 0);
        }
        any_derived |= shading == kShadingDerived;
    }
    if (any_derived) DeriveNormals(*dm, positions, materials, &out.normals);
    return out;
}

std::string CompressSideSection(std::string_view raw) {
    NAVE_CHECK_LT(raw.size(), size_t(LZ4_MAX_INPUT_SIZE))
        << "side section too large for one LZ4 block";
    const int bound = LZ4_compressBound(int(raw.size()));
    std::string out(8 + size_t(bound), '\0');
    const uint64_t raw_size = raw.size();
    std::memcpy(out.data(), &raw_size, 8);
    const int n = LZ4_compress_default(raw.data(), out.data() + 8, int(raw.size()), bound);
    NAVE_CHECK_GT(n, 0) << "LZ4 failed on " << raw.size() << " bytes";
    out.resize(8 + size_t(n));
    return out;
}

StatusOr<std::string> DecompressSideSection(std::string_view bytes, const std::string& what) {
    if (bytes.size() < 8) {
        return DataLossError("{}: side section of {} bytes is shorter than its 8-byte size field",
                             what, bytes.size());
    }
    uint64_t raw_size = 0;
    std::memcpy(&raw_size, bytes.data(), 8);
    // LZ4 expands at most 255:1, so a larger claim is corrupt; this also bounds the allocation.
    if (raw_size > uint64_t(LZ4_MAX_INPUT_SIZE) || raw_size > 255 * (bytes.size() - 8) + 16) {
        return DataLossError(
            "{}: side section claims {} bytes decompressed from {} (impossible for LZ4)", what,
            raw_size, bytes.size() - 8);
    }
    std::string out(raw_size, '\0');
    const int n =
        LZ4_decompress_safe(bytes.data() + 8, out.data(), int(bytes.size() - 8), int(raw_size));
    if (n < 0 || uint64_t(n) != raw_size) {
        return DataLossError(
            "{}: LZ4 cannot decompress the side section (result {}, expected {} bytes)", what, n,
            raw_size);
    }
    return out;
}

}  // namespace nave::store::codec
