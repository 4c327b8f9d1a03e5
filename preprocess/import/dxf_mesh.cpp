#include "preprocess/import/dxf_mesh.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>

#include "preprocess/import/text_parse.h"
#include "preprocess/import/triangulate.h"

namespace nave::preprocess {
namespace {

// A DXF file is pairs of lines: a group code, then its value (DXF Reference, "DXF Format").
struct Pair {
    int code = 0;
    std::string value;
    uint64_t line = 0;  ///< of the code, 1-based
};

class PairReader {
  public:
    explicit PairReader(std::ifstream& in) : in_(in) {}
    bool Next(Pair* pair) {
        std::string code;
        if (!std::getline(in_, code)) return false;
        pair->line = ++line_;
        if (!std::getline(in_, pair->value)) return false;
        ++line_;
        if (!pair->value.empty() && pair->value.back() == '\r') pair->value.pop_back();
        pair->code = std::atoi(code.c_str());
        return true;
    }

  private:
    std::ifstream& in_;
    uint64_t line_ = 0;
};

}  // namespace

StatusOr<std::vector<DxfMesh>> ReadDxfMeshEntities(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return IoError("{}: cannot open it", path.string());
    PairReader reader(in);
    std::vector<DxfMesh> meshes;
    Pair p;
    bool in_mesh = false;
    DxfMesh current;
    // The MESH entity's groups (DXF Reference, "MESH"): 92 the vertex count, then the vertices as
    // 10/20/30; 93 the size of the face list, then that many 90s: for each face its corner count
    // and its corners' vertex indices. Edges (94), creases (95) and overrides follow; not needed.
    uint64_t vertices_left = 0, face_items_left = 0, entity_line = 0;
    // 92 and 93 come again later in the entity (counts of overridden properties): only the first
    // of each is the level-0 mesh's.
    bool have_vertex_count = false, have_face_count = false;
    int axis = 0;
    std::vector<int64_t> face_items;
    std::vector<Vec3f> vertices;
    auto finish = [&]() -> Status {
        size_t i = 0;
        std::vector<std::array<uint32_t, 3>> triangles;
        std::vector<Vec3f> corners;
        while (i < face_items.size()) {
            const int64_t n = face_items[i++];
            if (n < 3 || size_t(n) > face_items.size() - i) {
                return DataLossError(
                    "{}:{}: MESH entity: a face of {} corners where {} items are left",
                    path.string(), entity_line, n, face_items.size() - i);
            }
            corners.clear();
            std::vector<uint32_t> ids;
            for (int64_t k = 0; k < n; ++k) {
                const int64_t v = face_items[i++];
                if (v < 0 || size_t(v) >= vertices.size()) {
                    return DataLossError("{}:{}: MESH entity: a face names vertex {} of {}",
                                         path.string(), entity_line, v, vertices.size());
                }
                ids.push_back(uint32_t(v));
                corners.push_back(vertices[size_t(v)]);
            }
            triangles.clear();
            TriangulatePolygon(corners, triangles);
            for (const auto& t : triangles) {
                for (uint32_t c : t) current.mesh.indices.push_back(ids[c]);
            }
        }
        current.mesh.positions = vertices;
        current.mesh.where = fmt::format("{}:{} MESH", path.filename().string(), entity_line);
        if (!current.mesh.indices.empty()) meshes.push_back(std::move(current));
        current = DxfMesh();
        return Status::Ok();
    };
    while (reader.Next(&p)) {
        if (p.code == 0) {
            if (in_mesh) {
                if (vertices_left > 0 || face_items_left > 0) {
                    return DataLossError(
                        "{}:{}: MESH entity ends with {} vertices and {} face items still to come",
                        path.string(), entity_line, vertices_left, face_items_left);
                }
                NAVE_RETURN_IF_ERROR(finish());
            }
            in_mesh = Trim(p.value) == "MESH";
            if (in_mesh) {
                entity_line = p.line;
                current = DxfMesh();
                vertices.clear();
                face_items.clear();
                vertices_left = face_items_left = 0;
                have_vertex_count = have_face_count = false;
            }
            continue;
        }
        if (!in_mesh) continue;
        switch (p.code) {
            case 8:
                current.layer = std::string(Trim(p.value));
                break;
            case 92:
                if (have_vertex_count) break;
                have_vertex_count = true;
                vertices_left = uint64_t(std::strtoull(p.value.c_str(), nullptr, 10));
                // Each vertex takes 6 lines: a count beyond the file is damage, not a reservation.
                vertices.reserve(size_t(std::min<uint64_t>(vertices_left, 1 << 20)));
                axis = 0;
                break;
            case 10:
            case 20:
            case 30:
                if (vertices_left == 0) break;  // the entity's own 10/20/30 elsewhere: not a vertex
                if (axis == 0) vertices.emplace_back();
                vertices.back()[axis] = float(std::strtod(p.value.c_str(), nullptr));
                if (++axis == 3) {
                    axis = 0;
                    --vertices_left;
                }
                break;
            case 93:
                if (have_face_count) break;
                have_face_count = true;
                face_items_left = uint64_t(std::strtoull(p.value.c_str(), nullptr, 10));
                break;
            case 90:
                if (face_items_left == 0) break;
                face_items.push_back(std::strtoll(p.value.c_str(), nullptr, 10));
                --face_items_left;
                break;
            default:
                break;
        }
    }
    if (in_mesh) NAVE_RETURN_IF_ERROR(finish());
    return meshes;
}

}  // namespace nave::preprocess
