#include "src/render/bricks/resident_mesh.h"

#include <algorithm>

#include "src/core/check.h"

namespace nave::render {
namespace {

/// Where each array starts in the region: cache-line aligned, in the order of the struct.
struct Layout {
    uint64_t positions = 0, normals = 0, uvs = 0, indices = 0, material_ids = 0, end = 0;
};

constexpr uint64_t kAlign = 64;

uint64_t AlignUp(uint64_t x) { return (x + kAlign - 1) / kAlign * kAlign; }

Layout LayoutOf(const MeshCounts& c) {
    Layout l;
    uint64_t at = 0;
    auto place = [&](uint64_t* offset, uint64_t bytes) {
        *offset = at;
        at = AlignUp(at + bytes);
    };
    place(&l.positions,
          (c.vertices + 1) * sizeof(Vec3f));  // + 1: Embree reads 16 bytes at the last vertex
    place(&l.normals, c.normals ? c.vertices * sizeof(Vec3f) : 0);
    place(&l.uvs, c.uvs ? c.vertices * sizeof(std::array<float, 2>) : 0);
    place(&l.indices, 3 * c.triangles * sizeof(uint32_t));
    place(&l.material_ids, c.triangles * sizeof(uint32_t));
    l.end = at;
    return l;
}

}  // namespace

uint64_t ResidentMesh::MemoryBytesFor(const MeshCounts& counts) {
    return PageRegion::MappedBytes(LayoutOf(counts).end);
}

StatusOr<ResidentMesh> ResidentMesh::Allocate(const MeshCounts& counts, Writable* writable) {
    const Layout l = LayoutOf(counts);
    ResidentMesh mesh;
    NAVE_ASSIGN_OR_RETURN(mesh.region_, PageRegion::Map(l.end));
    std::byte* base = mesh.region_.data();
    Writable w;
    w.positions = {reinterpret_cast<Vec3f*>(base + l.positions), counts.vertices};
    if (counts.normals) w.normals = {reinterpret_cast<Vec3f*>(base + l.normals), counts.vertices};
    if (counts.uvs)
        w.uvs = {reinterpret_cast<std::array<float, 2>*>(base + l.uvs), counts.vertices};
    w.indices = {reinterpret_cast<uint32_t*>(base + l.indices), 3 * counts.triangles};
    w.material_ids = {reinterpret_cast<uint32_t*>(base + l.material_ids), counts.triangles};
    mesh.positions = w.positions;
    mesh.normals = w.normals;
    mesh.uvs = w.uvs;
    mesh.indices = w.indices;
    mesh.material_ids = w.material_ids;
    if (writable != nullptr) *writable = w;
    return mesh;
}

StatusOr<ResidentMesh> ResidentMesh::CopyOf(const store::BrickMesh& m) {
    NAVE_CHECK(m.normals.empty() || m.normals.size() == m.positions.size())
        << "normals not one per vertex";
    NAVE_CHECK(m.uvs.empty() || m.uvs.size() == m.positions.size()) << "uvs not one per vertex";
    NAVE_CHECK_EQ(m.indices.size(), 3 * m.material_ids.size())
        << "material ids not one per triangle";
    Writable w;
    NAVE_ASSIGN_OR_RETURN(
        ResidentMesh mesh,
        Allocate({m.VertexCount(), m.TriangleCount(), m.HasNormals(), m.HasUvs()}, &w));
    std::copy(m.positions.begin(), m.positions.end(), w.positions.begin());
    std::copy(m.normals.begin(), m.normals.end(), w.normals.begin());
    std::copy(m.uvs.begin(), m.uvs.end(), w.uvs.begin());
    std::copy(m.indices.begin(), m.indices.end(), w.indices.begin());
    std::copy(m.material_ids.begin(), m.material_ids.end(), w.material_ids.begin());
    return mesh;
}

}  // namespace nave::render
