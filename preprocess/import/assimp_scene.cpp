#include "preprocess/import/assimp_scene.h"

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>
#include <fmt/format.h>

namespace nave::preprocess {

std::string AssimpVersion() {
    return fmt::format("Assimp {}.{}.{}", aiGetVersionMajor(), aiGetVersionMinor(),
                       aiGetVersionPatch());
}

StatusOr<ImportedModel> ReadWithAssimpInProcess(const std::filesystem::path& path) {
    // Triangulate polygons, bake node transforms into world-space meshes, drop points and lines.
    const unsigned flags =
        aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType;
    const aiScene* scene = aiImportFile(path.c_str(), flags);
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
    return model;
}

}  // namespace nave::preprocess
