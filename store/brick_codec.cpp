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
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>

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
// A face is flat when every corner normal is within 0.8 degrees of its geometric normal (cos >=
// 0.9999): ten-bit octahedral normals, what smooth faces keep, already err by up to ~0.2 degrees.
constexpr double kFlatCosine = 0.9999;

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

}  // namespace

uint64_t DecodedBytes(uint64_t vertex_count, uint64_t triangle_count, bool has_normals,
                      bool has_uvs) {
    return vertex_count * (sizeof(Vec3f) + (has_normals ? sizeof(Vec3f) : 0) +
                           (has_uvs ? sizeof(std::array<float, 2>) : 0)) +
           triangle_count * (3 * sizeof(uint32_t) + sizeof(uint32_t));
}

StatusOr<EncodedMesh> EncodeMeshSection(const BrickMesh& mesh, const GlobalGrid& grid,
                                        const EncodeOptions& options) {
    if (!(grid.step > 0) || !std::isfinite(grid.step) || !IsFinite(grid.origin)) {
        return InvalidArgumentError(
            "invalid grid: origin {}, step {} (the step must be finite and > 0)",
            fmt::streamed(grid.origin), grid.step);
    }
    if (options.draco_speed < 0 || options.draco_speed > 10) {
        return InvalidArgumentError("draco speed {} out of range [0, 10]", options.draco_speed);
    }
    if (options.normal_bits < 2 || options.normal_bits > 30 || options.uv_bits < 1 ||
        options.uv_bits > 30) {
        return InvalidArgumentError(
            "normal bits {} (expected 2..30) or uv bits {} (expected 1..30) out of range",
            options.normal_bits, options.uv_bits);
    }
    const size_t vertex_count = mesh.VertexCount();
    const size_t triangle_count = mesh.TriangleCount();

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

    // 4. Flat faces: a face whose corner normals all lie along its geometric normal (within
    // kFlatCosine) needs no normals, since the renderer falls back to the geometric normal. Its
    // corners are then joined by grid point (and texture coordinates) rather than by input vertex,
    // so the faces of faceted stones, whose inputs split every corner by normal, share their
    // vertices again: fewer points to decode, store and keep resident (docs/store-format.md).
    std::vector<uint8_t> flat(kept.size(), 1);
    size_t flat_count = kept.size();
    if (mesh.HasNormals()) {
        flat_count = 0;
        for (size_t k = 0; k < kept.size(); ++k) {
            const uint32_t* corner = &mesh.indices[3 * size_t(kept[k])];
            const Vec3i &q0 = q[corner[0]], &q1 = q[corner[1]], &q2 = q[corner[2]];
            const double e1[3] = {double(q1.x) - q0.x, double(q1.y) - q0.y, double(q1.z) - q0.z};
            const double e2[3] = {double(q2.x) - q0.x, double(q2.y) - q0.y, double(q2.z) - q0.z};
            const double ng[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                  e1[0] * e2[1] - e1[1] * e2[0]};
            const double ng_len = std::sqrt(ng[0] * ng[0] + ng[1] * ng[1] + ng[2] * ng[2]);
            bool is_flat = ng_len > 0;
            for (int c = 0; c < 3 && is_flat; ++c) {
                const Vec3f& n = mesh.normals[corner[c]];
                const double n_len =
                    std::sqrt(double(n.x) * n.x + double(n.y) * n.y + double(n.z) * n.z);
                const double cosine = (ng[0] * n.x + ng[1] * n.y + ng[2] * n.z) / (ng_len * n_len);
                is_flat = std::fabs(cosine) >= kFlatCosine;  // the renderer orients by winding
            }
            flat[k] = uint8_t(is_flat);
            flat_count += flat[k];
        }
    }
    out.has_normals = mesh.HasNormals() && flat_count < kept.size();
    // Flat faces are marked in the material attribute only when some faces keep normals.
    const bool mark_flat = out.has_normals && flat_count > 0;

    // 5. Points: a smooth face's corner is one point per (input vertex, material) pair (its normal
    // and uv are the vertex's); a flat face's corner is one point per (grid point, material, uv).
    // A point is never shared by a flat and a smooth face (their material values differ when
    // marked), so decoding can clear the normals of flat faces' points.
    constexpr uint32_t kUnset = 0xffffffffu;
    std::vector<uint32_t> point_of_vertex(vertex_count, kUnset);
    std::vector<uint32_t> material_of_vertex(vertex_count, 0);
    std::unordered_map<uint64_t, uint32_t> extra_points;
    // Flat corners' points by (grid point, material, uv): open addressing with linear probing
    // (std::unordered_map allocated a node per point). At most 3 points per flat face, so a table of
    // 4 slots per flat face is at most three quarters full.
    struct FlatKey {
        uint32_t position, material;
        uint64_t uv_bits;
        bool operator==(const FlatKey& o) const {
            return position == o.position && material == o.material && uv_bits == o.uv_bits;
        }
    };
    struct FlatEntry {
        FlatKey key;
        uint32_t point;
    };
    std::vector<FlatEntry> flat_entries;
    size_t flat_slots = 16;
    while (flat_slots < 4 * flat_count + 16) flat_slots <<= 1;
    std::vector<uint32_t> flat_table(flat_count > 0 ? flat_slots : 0, kUnset);  // index into flat_entries
    std::vector<uint32_t> point_vertex, point_material;
    std::vector<uint8_t> point_flat;
    std::vector<uint32_t> faces(3 * kept.size());
    Vec3i lo{std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::max(),
             std::numeric_limits<int32_t>::max()};
    Vec3i hi{std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::min(),
             std::numeric_limits<int32_t>::min()};
    auto new_point = [&](uint32_t v, uint32_t material, bool is_flat) {
        point_vertex.push_back(v);
        point_material.push_back(material);
        point_flat.push_back(uint8_t(is_flat));
        lo = Min(lo, q[v]);
        hi = Max(hi, q[v]);
        return uint32_t(point_vertex.size() - 1);
    };
    for (size_t k = 0; k < kept.size(); ++k) {
        const uint32_t t = kept[k];
        const uint32_t material = mesh.material_ids[t];
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = mesh.indices[3 * size_t(t) + c];
            uint32_t point;
            if (flat[k]) {
                uint64_t uv_bits = 0;
                if (out.has_uvs) std::memcpy(&uv_bits, mesh.uvs[v].data(), sizeof(uv_bits));
                const FlatKey key{position_value[v], material, uv_bits};
                uint64_t h = (uint64_t(key.position) << 32 | key.material) * 0x9e3779b97f4a7c15ull;
                h ^= (key.uv_bits + 0x7f4a7c159e3779b9ull + (h << 6) + (h >> 2)) * 0xbf58476d1ce4e5b9ull;
                size_t slot = size_t(h ^ (h >> 31)) & (flat_slots - 1);
                while (flat_table[slot] != kUnset && !(flat_entries[flat_table[slot]].key == key))
                    slot = (slot + 1) & (flat_slots - 1);
                if (flat_table[slot] == kUnset) {
                    flat_table[slot] = uint32_t(flat_entries.size());
                    flat_entries.push_back({key, new_point(v, material, true)});
                }
                point = flat_entries[flat_table[slot]].point;
            } else if (point_of_vertex[v] == kUnset) {
                point = point_of_vertex[v] = new_point(v, material, false);
                material_of_vertex[v] = material;
            } else if (material_of_vertex[v] == material) {
                point = point_of_vertex[v];
            } else {
                const uint64_t key = (uint64_t(v) << 32) | material;
                auto it = extra_points.find(key);
                point =
                    it != extra_points.end()
                        ? it->second
                        : extra_points.emplace(key, new_point(v, material, false)).first->second;
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
    const int32_t prefix[4] = {base.x, base.y, base.z,
                               int32_t(mark_flat ? kMeshFlagFlatFaces : 0u)};
    std::memcpy(out.bytes.data(), prefix, kMeshPrefixBytes);

    if (!kept.empty()) {
        draco::Mesh dm;
        dm.set_num_points(uint32_t(point_count));
        // Positions: distinct grid points, mapped from points.
        auto pos = NewAttribute(kPositionType, 3, draco::DT_INT32, unique_positions.size());
        for (size_t i = 0; i < unique_positions.size(); ++i) {
            const Vec3i& g = unique_positions[i];
            const int32_t rel[3] = {g.x - base.x, g.y - base.y, g.z - base.z};
            pos->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), rel);
        }
        pos->SetExplicitMapping(point_count);
        for (size_t p = 0; p < point_count; ++p) {
            pos->SetPointMapEntry(draco::PointIndex(uint32_t(p)),
                                  draco::AttributeValueIndex(position_value[point_vertex[p]]));
        }
        const int pos_id = dm.AddAttribute(std::move(pos));
        int normal_id = -1, uv_id = -1;
        if (out.has_normals) {
            auto att = NewAttribute(kNormalType, 3, draco::DT_FLOAT32, point_count);
            for (size_t p = 0; p < point_count; ++p) {
                // Flat faces' points carry one constant (cheap to code); decoding clears them.
                const Vec3f n =
                    point_flat[p] ? Vec3f(0, 0, 1) : Normalized(mesh.normals[point_vertex[p]]);
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
                const int32_t m = mark_flat ? int32_t(point_material[p] << 1 | point_flat[p])
                                            : int32_t(point_material[p]);
                att->SetAttributeValue(draco::AttributeValueIndex(uint32_t(p)), &m);
            }
            dm.AddAttribute(std::move(att));
        }
        for (size_t k = 0; k < kept.size(); ++k) {
            dm.AddFace({draco::PointIndex(faces[3 * k]), draco::PointIndex(faces[3 * k + 1]),
                        draco::PointIndex(faces[3 * k + 2])});
        }

        draco::ExpertEncoder encoder(dm);
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
    }

    // 7. Decode once: the store must never hold a brick that does not decode to what was given, and
    // the decoded vertex count (Draco splits vertices at attribute seams and non-manifold edges) is
    // only known after decoding.
    NAVE_ASSIGN_OR_RETURN(
        BrickMesh decoded,
        DecodeMeshSection(out.bytes, grid, uint64_t(out.max_material_id) + 1, "encoded brick"));
    if (decoded.TriangleCount() != kept.size()) {
        return InternalError("Draco round trip lost triangles: encoded {}, decoded {}", kept.size(),
                             decoded.TriangleCount());
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
    out.triangle_count = decoded.TriangleCount();
    out.vertex_count = decoded.VertexCount();
    out.decoded_bytes =
        DecodedBytes(out.vertex_count, out.triangle_count, out.has_normals, out.has_uvs);
    for (const Vec3f& p : decoded.positions) out.geometry_bounds.Extend(p);
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
    if ((flags & ~kMeshFlagFlatFaces) != 0) {
        return DataLossError(
            "{}: mesh section flags 0x{:x} hold bits this nave does not know (0x{:x})", what, flags,
            flags & ~kMeshFlagFlatFaces);
    }
    const bool flat_marked = (flags & kMeshFlagFlatFaces) != 0;
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
    // Exact sizes, so that MemoryBytes() equals DecodedBytes() and the directory's decoded_bytes.
    out.positions.resize(point_count);
    if (normal != nullptr) out.normals.resize(point_count);
    if (uv != nullptr) out.uvs.resize(point_count);
    out.indices.resize(3 * size_t(face_count));
    out.material_ids.resize(face_count);
    // Values are read straight from the attributes' buffers (the point-to-value mapping, then the
    // value's address): Draco's per-value GetValue/ConvertValue calls cost more than the decode
    // itself on large bricks (bench_brick_load).
    const PlainAttribute positions(*pos);
    for (uint32_t p = 0; p < point_count; ++p) {
        const int32_t* g = positions.Value<int32_t>(p);
        out.positions[p] = grid.Dequantize({base.x + g[0], base.y + g[1], base.z + g[2]});
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
        const int32_t m = flat_marked ? value >> 1 : value;
        if (m < 0 || uint64_t(m) >= material_count) {
            return DataLossError("{}: triangle {} has material {} but the store has {} materials",
                                 what, f, m, material_count);
        }
        out.material_ids[f] = uint32_t(m);
        if (flat_marked && (value & 1) != 0 && normal != nullptr) {
            // A flat face: zero normals tell the renderer to shade with the geometric normal.
            for (int c = 0; c < 3; ++c) out.normals[face[c].value()] = Vec3f(0, 0, 0);
        }
    }
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
