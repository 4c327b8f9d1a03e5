#include "preprocess/import/assimp_scene.h"

#include <assimp/cimport.h>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>
#include <fmt/format.h>

#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>

#include "preprocess/import/dxf_mesh.h"
#include "preprocess/import/file_extension.h"
#include "preprocess/import/material_table.h"

namespace nave::preprocess {

std::string AssimpVersion() {
    return fmt::format("Assimp {}.{}.{}", aiGetVersionMajor(), aiGetVersionMinor(),
                       aiGetVersionPatch());
}

namespace {

// DXF: one material per layer and colour (Assimp gives each layer as a mesh named after it, and
// each entity's colour, from its ACI index or the layer's, as vertex colours), named after the
// layer; a layer of several colours gets "layer #2"... for the second. Meshes are split by colour
// so that every triangle keeps its own.
void TakeDxfLayersAsMaterials(const aiScene* scene, std::vector<DxfMesh> mesh_entities,
                              ImportedModel& model) {
    std::vector<IndexedMesh> split;
    std::vector<store::MaterialRecord> materials;
    MaterialTable table(materials);
    size_t kept = 0;
    for (unsigned mi = 0; scene != nullptr && mi < scene->mNumMeshes; ++mi) {
        const aiMesh* src = scene->mMeshes[mi];
        if ((src->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
        IndexedMesh& mesh = model.meshes[kept++];
        const std::string layer = src->mName.length > 0 ? src->mName.C_Str() : "0";
        std::map<uint32_t, IndexedMesh> by_material;
        for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            std::optional<std::array<float, 4>> rgb;
            const uint32_t first = mesh.indices[t];
            if (src->mColors[0] != nullptr && first < src->mNumVertices) {
                const aiColor4D& c = src->mColors[0][first];
                rgb = {c.r, c.g, c.b, 1.f};
            }
            const uint32_t material = table.Find(layer, rgb);
            IndexedMesh& part = by_material[material];
            // Positions are copied per triangle: a DXF face owns its corners anyway.
            for (int k = 0; k < 3; ++k) {
                const uint32_t v = mesh.indices[t + k];
                part.indices.push_back(uint32_t(part.positions.size()));
                part.positions.push_back(v < mesh.positions.size() ? mesh.positions[v] : Vec3f());
                if (!mesh.normals.empty()) {
                    part.normals.push_back(v < mesh.normals.size() ? mesh.normals[v] : Vec3f());
                }
            }
        }
        for (auto& [material, part] : by_material) {
            part.material = material;
            part.where = fmt::format("{} layer '{}'", mesh.where, layer);
            split.push_back(std::move(part));
        }
    }
    // The MESH entities nave read itself (dxf_mesh.h): their layer, no colour.
    for (DxfMesh& entity : mesh_entities) {
        entity.mesh.material = table.Find(entity.layer, std::nullopt);
        entity.mesh.where += fmt::format(" layer '{}'", entity.layer);
        split.push_back(std::move(entity.mesh));
    }
    model.meshes = std::move(split);
    model.materials = std::move(materials);
}

}  // namespace

StatusOr<ImportedModel> ReadWithAssimpInProcess(const std::filesystem::path& path) {
    // Triangulate polygons, bake node transforms into world-space meshes, drop points and lines.
    const unsigned flags =
        aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
    const bool dxf = LowerExtension(path) == ".dxf";
    std::vector<DxfMesh> mesh_entities;
    if (dxf) {
        NAVE_ASSIGN_OR_RETURN(mesh_entities, ReadDxfMeshEntities(path));
    }
    // A DXF file's layers are Assimp's meshes (named after them) under one default material:
    // baking the transforms must not join them, so that each layer can become a material.
    aiPropertyStore* properties = aiCreatePropertyStore();
    aiSetImportPropertyInteger(properties, AI_CONFIG_PP_PTV_KEEP_HIERARCHY, dxf ? 1 : 0);
    const aiScene* scene = aiImportFileExWithProperties(path.c_str(), flags, nullptr, properties);
    aiReleasePropertyStore(properties);
    // A drawing of MESH entities alone is "no 3d data" to Assimp: nave's own reader has it.
    if (dxf && scene == nullptr && !mesh_entities.empty()) {
        ImportedModel model;
        TakeDxfLayersAsMaterials(nullptr, std::move(mesh_entities), model);
        return model;
    }
    if (scene == nullptr) {
        return InvalidArgumentError("{}: Assimp cannot read it: {}", path.string(),
                                    aiGetErrorString());
    }
    struct Release {
        const aiScene* s;
        ~Release() { aiReleaseImport(s); }
    } release{scene};
    const std::string file = path.filename().string();
    ImportedModel model;
    std::vector<store::MaterialRecord>& materials = model.materials;
    for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
        const aiMaterial* src = scene->mMaterials[i];
        store::MaterialRecord m;
        aiString name;
        m.name = aiGetMaterialString(src, AI_MATKEY_NAME, &name) == AI_SUCCESS && name.length > 0
                     ? std::string(name.C_Str())
                     : fmt::format("material_{}", i);
        aiColor4D c;
        if (aiGetMaterialColor(src, AI_MATKEY_COLOR_DIFFUSE, &c) == AI_SUCCESS)
            m.diffuse = {c.r, c.g, c.b};
        if (aiGetMaterialColor(src, AI_MATKEY_COLOR_SPECULAR, &c) == AI_SUCCESS)
            m.specular = {c.r, c.g, c.b};
        if (aiGetMaterialColor(src, AI_MATKEY_COLOR_EMISSIVE, &c) == AI_SUCCESS)
            m.emission = {c.r, c.g, c.b};
        float f = 0;
        if (aiGetMaterialFloat(src, AI_MATKEY_OPACITY, &f) == AI_SUCCESS) m.opacity = f;
        if (aiGetMaterialFloat(src, AI_MATKEY_SHININESS, &f) == AI_SUCCESS) m.shininess = f;
        if (aiGetMaterialFloat(src, AI_MATKEY_REFRACTI, &f) == AI_SUCCESS) m.ior = f;
        aiString tex;
        if (aiGetMaterialTexture(src, aiTextureType_DIFFUSE, 0, &tex) == AI_SUCCESS)
            m.textures["map_Kd"] = tex.C_Str();
        if (aiGetMaterialTexture(src, aiTextureType_NORMALS, 0, &tex) == AI_SUCCESS)
            m.textures["norm"] = tex.C_Str();
        materials.push_back(std::move(m));
    }
    std::vector<IndexedMesh>& meshes = model.meshes;
    for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
        const aiMesh* src = scene->mMeshes[mi];
        if ((src->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
        IndexedMesh out;
        out.where = fmt::format("{} mesh {}", file, mi);
        out.material = src->mMaterialIndex;
        out.positions.resize(src->mNumVertices);
        for (unsigned v = 0; v < src->mNumVertices; ++v) {
            out.positions[v] = Vec3f(src->mVertices[v].x, src->mVertices[v].y, src->mVertices[v].z);
        }
        if (src->mNormals != nullptr) {
            out.normals.resize(src->mNumVertices);
            for (unsigned v = 0; v < src->mNumVertices; ++v) {
                out.normals[v] = Vec3f(src->mNormals[v].x, src->mNormals[v].y, src->mNormals[v].z);
            }
        }
        if (src->mTextureCoords[0] != nullptr) {
            out.uvs.resize(src->mNumVertices);
            for (unsigned v = 0; v < src->mNumVertices; ++v) {
                out.uvs[v] = {src->mTextureCoords[0][v].x, src->mTextureCoords[0][v].y};
            }
        }
        for (unsigned f = 0; f < src->mNumFaces; ++f) {
            const aiFace& face = src->mFaces[f];
            if (face.mNumIndices != 3) continue;
            out.indices.insert(out.indices.end(),
                               {face.mIndices[0], face.mIndices[1], face.mIndices[2]});
        }
        meshes.push_back(std::move(out));
    }
    if (dxf) TakeDxfLayersAsMaterials(scene, std::move(mesh_entities), model);
    return model;
}

}  // namespace nave::preprocess
