#include "preprocess/import/importer.h"

#include <cctype>
#include <cstdio>
#include <cstring>

#include "preprocess/import/assimp_importer.h"
#include "preprocess/import/cad_importer.h"
#include "preprocess/import/file_extension.h"
#include "preprocess/import/gltf_importer.h"
#include "preprocess/import/obj_importer.h"
#include "preprocess/import/ply_importer.h"
#include "preprocess/import/stl_importer.h"
#include "preprocess/merged_source.h"

namespace nave::preprocess {
namespace {

// The first bytes, to recognise files by content when the extension says nothing.
std::string Sniff(const std::filesystem::path& path) {
    char bytes[16] = {};
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) return {};
    size_t got = std::fread(bytes, 1, sizeof(bytes), f);
    std::fclose(f);
    return std::string(bytes, got);
}

}  // namespace

StatusOr<std::unique_ptr<TriangleSource>> OpenModel(const std::filesystem::path& path,
                                                    double precision) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return NotFoundError("{}: no such file", path.string());
    if (std::filesystem::file_size(path, ec) == 0 && !ec) {
        return InvalidArgumentError("{}: empty file: expected a model", path.string());
    }
    const std::string ext = LowerExtension(path);
    if (ext == ".obj") return OpenObj(path);
    if (ext == ".ply") return OpenPly(path);
    if (ext == ".stl") return OpenStl(path);
    if (ext == ".gltf" || ext == ".glb") return OpenGltf(path);
    if (IsCadFile(path)) return OpenCad(path, precision);
    std::string head = Sniff(path);
    // DWG is Autodesk's closed format: no library in Debian reads it. Its files start with the
    // AutoCAD release ("AC1032" for AutoCAD 2018).
    if (ext == ".dwg" || (head.rfind("AC10", 0) == 0 && head.size() >= 6 &&
                          std::isdigit(static_cast<unsigned char>(head[4])) != 0)) {
        return UnsupportedError(
            "{}: a DWG drawing, which nave cannot read (no open library reads DWG): export it "
            "from AutoCAD or its viewer as DXF (3D faces or meshes), or as STEP, IFC or OBJ, and "
            "give nave that file",
            path.string());
    }
    if (head.rfind("ply", 0) == 0) return OpenPly(path);
    if (head.rfind("glTF", 0) == 0) return OpenGltf(path);
    if (!ext.empty() && AssimpSupports(path)) return OpenWithAssimp(path);
    return UnsupportedError(
        "{}: unknown model format '{}': nave reads .obj, .ply, .stl, .gltf, .glb, .step, .stp, "
        ".iges, .igs and what Assimp reads (.fbx, .dae, .3ds, .dxf, ...)",
        path.string(), ext.empty() ? "(none)" : ext);
}

StatusOr<std::unique_ptr<TriangleSource>> OpenModels(
    const std::vector<std::filesystem::path>& paths, double precision) {
    if (paths.empty()) return InvalidArgumentError("no input model given");
    std::vector<std::unique_ptr<TriangleSource>> sources;
    for (const auto& p : paths) {
        NAVE_ASSIGN_OR_RETURN(auto source, OpenModel(p, precision));
        sources.push_back(std::move(source));
    }
    return std::unique_ptr<TriangleSource>(new MergedSource(std::move(sources)));
}

}  // namespace nave::preprocess
