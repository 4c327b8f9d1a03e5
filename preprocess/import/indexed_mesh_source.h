#pragma once
// A model already in memory as indexed meshes (what glTF and Assimp give), served as a
// TriangleSource. These formats are not streamed: their libraries load the whole file, so they suit
// models that fit in memory (memory_bytes() says how much they hold).

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

/// One mesh in world space: positions already transformed by its node, one material.
struct IndexedMesh {
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;             ///< empty or one per position
    std::vector<std::array<float, 2>> uvs;  ///< empty or one per position
    std::vector<uint32_t> indices;          ///< 3 per triangle
    uint32_t material = 0;
    std::string where;  ///< "helmet.gltf mesh 0 primitive 1", for warnings
};

class IndexedMeshSource final : public TriangleSource {
  public:
    IndexedMeshSource(std::string name, std::string units, std::vector<IndexedMesh> meshes,
                      std::vector<store::MaterialRecord> materials, ImportWarnings warnings);

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override;
    const std::vector<store::MaterialRecord>& materials() const override { return materials_; }
    std::string name() const override { return name_; }
    std::string units() const override { return units_; }
    std::string content() const override { return content_; }
    void SetContent(std::string content) { content_ = std::move(content); }
    uint64_t progress_done() const override { return done_; }
    uint64_t progress_total() const override { return total_; }
    std::string progress_unit() const override { return "triangles"; }
    uint64_t memory_bytes() const override;
    const ImportWarnings& warnings() const override { return warnings_; }
    /// Writes the embedded images handed to SetEmbeddedImages under their names.
    Status WriteGeneratedTextures(const std::filesystem::path& dir) const override;
    /// Images the model file carries inside it (glTF buffer views, data URIs): file name -> encoded
    /// bytes. The materials name them; WriteGeneratedTextures puts them where the texture
    /// conversion finds them.
    void SetEmbeddedImages(std::vector<std::pair<std::string, std::string>> images) {
        embedded_images_ = std::move(images);
    }
    /// Meshes that arrive one at a time (read from a file in order, cad_importer.cpp): once the
    /// meshes given to the constructor are used up, `feed(&mesh)` is called for the next one
    /// until it returns false; each replaces the last, so one mesh is held at a time.
    /// `total_triangles` is the progress total over all of them.
    using MeshFeed = std::function<StatusOr<bool>(IndexedMesh* next)>;
    void SetMeshFeed(MeshFeed feed, uint64_t total_triangles) {
        feed_ = std::move(feed);
        total_ = total_triangles;
    }

  private:
    MeshFeed feed_;
    std::vector<std::pair<std::string, std::string>> embedded_images_;
    std::string name_, units_, content_;
    std::vector<IndexedMesh> meshes_;
    std::vector<store::MaterialRecord> materials_;
    ImportWarnings warnings_;
    size_t mesh_ = 0, triangle_ = 0;
    uint64_t done_ = 0, total_ = 0, emitted_ = 0;
};

}  // namespace nave::preprocess
