#include "preprocess/import/indexed_mesh_source.h"

#include <fmt/format.h>

#include "preprocess/import/triangle_check.h"
#include "src/core/file.h"

namespace nave::preprocess {

Status IndexedMeshSource::WriteGeneratedTextures(const std::filesystem::path& dir) const {
    for (const auto& [name, bytes] : embedded_images_) {
        NAVE_ASSIGN_OR_RETURN(AtomicFile file, AtomicFile::Create(dir / name));
        NAVE_RETURN_IF_ERROR(file.Write(bytes.data(), bytes.size()));
        NAVE_RETURN_IF_ERROR(file.Commit());
    }
    return Status::Ok();
}

IndexedMeshSource::IndexedMeshSource(std::string name, std::string units,
                                     std::vector<IndexedMesh> meshes,
                                     std::vector<store::MaterialRecord> materials,
                                     ImportWarnings warnings)
    : name_(std::move(name)),
      units_(std::move(units)),
      meshes_(std::move(meshes)),
      materials_(std::move(materials)),
      warnings_(std::move(warnings)) {
    if (materials_.empty()) {
        store::MaterialRecord m;
        m.name = "default";
        materials_.push_back(m);
    }
    for (const IndexedMesh& m : meshes_) total_ += m.indices.size() / 3;
}

uint64_t IndexedMeshSource::memory_bytes() const {
    uint64_t bytes = 0;
    for (const IndexedMesh& m : meshes_) {
        bytes += m.positions.capacity() * 12 + m.normals.capacity() * 12 + m.uvs.capacity() * 8 +
                 m.indices.capacity() * 4;
    }
    return bytes;
}

StatusOr<bool> IndexedMeshSource::Next(std::vector<Triangle>& batch, size_t max_triangles) {
    batch.clear();
    while (batch.size() < max_triangles) {
        if (mesh_ == meshes_.size()) {
            if (!feed_) break;
            IndexedMesh next;
            NAVE_ASSIGN_OR_RETURN(const bool more, feed_(&next));
            meshes_.clear();
            mesh_ = 0;
            triangle_ = 0;
            if (!more) {
                feed_ = nullptr;
                break;
            }
            meshes_.push_back(std::move(next));
        }
        const IndexedMesh& m = meshes_[mesh_];
        if (triangle_ * 3 >= m.indices.size()) {
            ++mesh_;
            triangle_ = 0;
            continue;
        }
        Triangle t;
        t.material = m.material < materials_.size() ? m.material : 0;
        t.has_normals = !m.normals.empty();
        t.has_uvs = !m.uvs.empty();
        bool in_range = true;
        for (int j = 0; j < 3; ++j) {
            uint32_t i = m.indices[triangle_ * 3 + j];
            if (i >= m.positions.size()) {
                in_range = false;
                break;
            }
            t.p[j] = m.positions[i];
            if (t.has_normals) t.n[j] = m.normals[i];
            if (t.has_uvs) t.uv[j] = m.uvs[i];
        }
        std::string where;
        if (!in_range) {
            warnings_.Add("triangles with out-of-range indices skipped",
                          fmt::format("{} triangle {}", m.where, triangle_));
        } else if (AcceptTriangle(t, warnings_, m.where)) {
            batch.push_back(t);
            ++emitted_;
        }
        ++triangle_;
        ++done_;
    }
    if (batch.empty() && emitted_ == 0) {
        emitted_ = 1;  // report once
        return InvalidArgumentError("{}: no usable triangles", name_);
    }
    return !batch.empty();
}

}  // namespace nave::preprocess
