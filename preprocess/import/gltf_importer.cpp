#include "preprocess/import/gltf_importer.h"

#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <memory>

#include "preprocess/import/file_extension.h"
#include "preprocess/import/indexed_mesh_source.h"

namespace nave::preprocess {
namespace {

using Mat4 = std::array<double, 16>;  // column-major, as glTF stores it

Mat4 Identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 Mul(const Mat4& a, const Mat4& b) {
    Mat4 r{};
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    return r;
}

// glTF 2.0 spec, "Transformations": a node's matrix, or T * R * S from translation, rotation (unit
// quaternion x, y, z, w) and scale.
Mat4 NodeMatrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) {
        Mat4 m;
        for (int i = 0; i < 16; ++i) m[i] = node.matrix[i];
        return m;
    }
    Mat4 t = Identity(), r = Identity(), s = Identity();
    if (node.translation.size() == 3) {
        t[12] = node.translation[0];
        t[13] = node.translation[1];
        t[14] = node.translation[2];
    }
    if (node.rotation.size() == 4) {
        double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2],
               w = node.rotation[3];
        r = {1 - 2 * (y * y + z * z),
             2 * (x * y + z * w),
             2 * (x * z - y * w),
             0,
             2 * (x * y - z * w),
             1 - 2 * (x * x + z * z),
             2 * (y * z + x * w),
             0,
             2 * (x * z + y * w),
             2 * (y * z - x * w),
             1 - 2 * (x * x + y * y),
             0,
             0,
             0,
             0,
             1};
    }
    if (node.scale.size() == 3) {
        s[0] = node.scale[0];
        s[5] = node.scale[1];
        s[10] = node.scale[2];
    }
    return Mul(t, Mul(r, s));
}

Vec3f TransformPoint(const Mat4& m, const Vec3f& p) {
    return Vec3f(float(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12]),
                 float(m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13]),
                 float(m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]));
}

// Normals transform by the inverse transpose of the upper 3x3 (cofactor matrix, up to a positive
// scale when the determinant is positive; the sign of the determinant is applied so normals keep
// pointing out).
struct NormalMatrix {
    double m[9];
    bool flips = false;
};
NormalMatrix MakeNormalMatrix(const Mat4& a) {
    double a00 = a[0], a10 = a[1], a20 = a[2], a01 = a[4], a11 = a[5], a21 = a[6], a02 = a[8],
           a12 = a[9], a22 = a[10];
    NormalMatrix n;
    // Cofactors: row-major n.m[row * 3 + col].
    n.m[0] = a11 * a22 - a12 * a21;
    n.m[1] = a12 * a20 - a10 * a22;
    n.m[2] = a10 * a21 - a11 * a20;
    n.m[3] = a02 * a21 - a01 * a22;
    n.m[4] = a00 * a22 - a02 * a20;
    n.m[5] = a01 * a20 - a00 * a21;
    n.m[6] = a01 * a12 - a02 * a11;
    n.m[7] = a02 * a10 - a00 * a12;
    n.m[8] = a00 * a11 - a01 * a10;
    double det = a00 * n.m[0] + a01 * n.m[1] + a02 * n.m[2];
    n.flips = det < 0;
    return n;
}
Vec3f TransformNormal(const NormalMatrix& n, const Vec3f& v) {
    // Cofactor matrix C satisfies C = det * inverse^T; rows of C times v.
    Vec3d r(n.m[0] * v.x + n.m[3] * v.y + n.m[6] * v.z, n.m[1] * v.x + n.m[4] * v.y + n.m[7] * v.z,
            n.m[2] * v.x + n.m[5] * v.y + n.m[8] * v.z);
    if (n.flips) r = -r;
    double len = Length(r);
    return len > 0 ? Vec3f(r / len) : Vec3f(0, 0, 1);
}

/// Encoded images the file carries inside it (GLB buffer views, data URIs), by image index.
using EmbeddedImages = std::map<int, std::string>;

/// tinygltf's image loader: nave does not decode images here (the texture conversion does).
/// External files are kept by name; embedded images have no name (their uri is empty), so their
/// encoded bytes are kept.
bool KeepEmbeddedImageBytes(tinygltf::Image* image, const int image_index, std::string*,
                            std::string*, int, int, const unsigned char* bytes, int size,
                            void* user) {
    if (image->uri.empty() && bytes != nullptr && size > 0) {
        (*static_cast<EmbeddedImages*>(user))[image_index] =
            std::string(reinterpret_cast<const char*>(bytes), size_t(size));
    }
    return true;
}

/// The file extension of encoded image bytes by their signature, or empty if not PNG or JPEG.
std::string ImageExtension(const std::string& bytes) {
    if (bytes.size() >= 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) return "png";
    if (bytes.size() >= 3 && uint8_t(bytes[0]) == 0xFF && uint8_t(bytes[1]) == 0xD8 &&
        uint8_t(bytes[2]) == 0xFF)
        return "jpg";
    return {};
}

class GltfReader {
  public:
    GltfReader(const tinygltf::Model& model, std::string file)
        : model_(model), file_(std::move(file)) {}

    // Reads accessor `index` as `components` floats per element (VEC2/VEC3, float or normalized
    // ints).
    StatusOr<std::vector<float>> ReadFloats(int index, int components) {
        NAVE_ASSIGN_OR_RETURN(const tinygltf::Accessor* acc, Accessor(index));
        if (tinygltf::GetNumComponentsInType(acc->type) != components) {
            return InvalidArgumentError(
                "{}: accessor {} has {} components per element, expected {}", file_, index,
                tinygltf::GetNumComponentsInType(acc->type), components);
        }
        std::vector<float> out(acc->count * components);
        NAVE_RETURN_IF_ERROR(Walk(*acc, index, [&](const unsigned char* p, size_t i) {
            for (int c = 0; c < components; ++c) out[i * components + c] = Component(*acc, p, c);
        }));
        return out;
    }

    StatusOr<std::vector<uint32_t>> ReadIndices(int index) {
        NAVE_ASSIGN_OR_RETURN(const tinygltf::Accessor* acc, Accessor(index));
        std::vector<uint32_t> out(acc->count);
        int type = acc->componentType;
        if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
            return InvalidArgumentError(
                "{}: index accessor {} has component type {}: expected an unsigned "
                "integer type",
                file_, index, type);
        }
        NAVE_RETURN_IF_ERROR(Walk(*acc, index, [&](const unsigned char* p, size_t i) {
            if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE)
                out[i] = p[0];
            else if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
                uint16_t v;
                std::memcpy(&v, p, 2);
                out[i] = v;
            } else {
                uint32_t v;
                std::memcpy(&v, p, 4);
                out[i] = v;
            }
        }));
        return out;
    }

  private:
    StatusOr<const tinygltf::Accessor*> Accessor(int index) {
        if (index < 0 || size_t(index) >= model_.accessors.size()) {
            return InvalidArgumentError("{}: accessor {} out of range [0, {})", file_, index,
                                        model_.accessors.size());
        }
        return &model_.accessors[index];
    }

    template <typename F>
    Status Walk(const tinygltf::Accessor& acc, int index, F&& f) {
        if (acc.bufferView < 0 || size_t(acc.bufferView) >= model_.bufferViews.size()) {
            return InvalidArgumentError(
                "{}: accessor {} has no valid bufferView (sparse-only accessors are not "
                "supported)",
                file_, index);
        }
        const tinygltf::BufferView& view = model_.bufferViews[acc.bufferView];
        if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size()) {
            return InvalidArgumentError("{}: bufferView {} names buffer {}, out of range", file_,
                                        acc.bufferView, view.buffer);
        }
        const std::vector<unsigned char>& data = model_.buffers[view.buffer].data;
        const int component_bytes = tinygltf::GetComponentSizeInBytes(acc.componentType);
        const int components = tinygltf::GetNumComponentsInType(acc.type);
        if (component_bytes <= 0 || components <= 0) {
            return DataLossError("{}: accessor {} has an invalid componentType {} or type {}",
                                 file_, index, acc.componentType, acc.type);
        }
        const size_t elem = size_t(component_bytes) * size_t(components);
        const size_t stride = view.byteStride > 0 ? view.byteStride : elem;
        const size_t size = data.size();
        // Each step checked against what is left, never summed first: offsets and counts near 2^64
        // in a damaged file would wrap around and pass a summed check.
        const bool fits =
            view.byteOffset <= size && acc.byteOffset <= size - view.byteOffset &&
            elem <= size - view.byteOffset - acc.byteOffset &&
            acc.count - 1 <= (size - view.byteOffset - acc.byteOffset - elem) / stride;
        const size_t start = view.byteOffset + acc.byteOffset;
        if (acc.count > 0 && !fits) {
            return DataLossError(
                "{}: accessor {} reads {} elements of {} bytes at offset {} of buffer {} "
                "({} bytes): out of range",
                file_, index, acc.count, elem, start, view.buffer, data.size());
        }
        for (size_t i = 0; i < acc.count; ++i) f(data.data() + start + i * stride, i);
        return Status::Ok();
    }

    static float Component(const tinygltf::Accessor& acc, const unsigned char* p, int c) {
        switch (acc.componentType) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: {
                float v;
                std::memcpy(&v, p + 4 * c, 4);
                return v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
                return p[c] / 255.f;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                uint16_t v;
                std::memcpy(&v, p + 2 * c, 2);
                return v / 65535.f;
            }
            case TINYGLTF_COMPONENT_TYPE_BYTE:
                return std::max(int8_t(p[c]) / 127.f, -1.f);
            case TINYGLTF_COMPONENT_TYPE_SHORT: {
                int16_t v;
                std::memcpy(&v, p + 2 * c, 2);
                return std::max(v / 32767.f, -1.f);
            }
            default:
                return 0.f;
        }
    }

    const tinygltf::Model& model_;
    std::string file_;
};

/// The file a texture's image is read from: its uri, or for an embedded image the name it is
/// written under
/// ("helmet.image3.png", see KeepEmbeddedImageBytes), or empty when it has neither.
std::string TextureName(const tinygltf::Model& model, int texture, const EmbeddedImages& embedded,
                        const std::string& stem) {
    if (texture < 0 || size_t(texture) >= model.textures.size()) return {};
    int source = model.textures[texture].source;
    if (source < 0 || size_t(source) >= model.images.size()) return {};
    const tinygltf::Image& image = model.images[source];
    if (!image.uri.empty()) return image.uri;
    auto it = embedded.find(source);
    if (it == embedded.end() || ImageExtension(it->second).empty()) return {};
    return fmt::format("{}.image{}.{}", stem, source, ImageExtension(it->second));
}

}  // namespace

StatusOr<std::unique_ptr<TriangleSource>> OpenGltf(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return NotFoundError("{}: no such file", path.string());
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    EmbeddedImages embedded;
    loader.SetImageLoader(KeepEmbeddedImageBytes, &embedded);
    std::string err, warn;
    const std::string ext = LowerExtension(path);
    bool ok = false;
    try {
        ok = ext == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, path.string())
                           : loader.LoadASCIIFromFile(&model, &err, &warn, path.string());
    } catch (const std::exception& e) {
        // tinygltf indexes some arrays with at(), which throws on a damaged index
        // (FuzzRegression.GltfIndexOutOfRangeIsAnError).
        return InvalidArgumentError(
            "{}: not a valid glTF 2.0 file: the glTF reader failed on it "
            "({})",
            path.string(), e.what());
    }
    if (!ok) return InvalidArgumentError("{}: not a valid glTF 2.0 file: {}", path.string(), err);
    std::string file = path.filename().string();
    ImportWarnings warnings;
    if (!warn.empty()) warnings.Add("glTF loader warnings", file + ": " + warn.substr(0, 200));

    std::vector<store::MaterialRecord> materials;
    for (size_t i = 0; i < model.materials.size(); ++i) {
        const tinygltf::Material& src = model.materials[i];
        store::MaterialRecord m;
        m.name = src.name.empty() ? fmt::format("material_{}", i) : src.name;
        const auto& pbr = src.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() == 4) {
            for (int c = 0; c < 3; ++c) m.diffuse[c] = float(pbr.baseColorFactor[c]);
            m.opacity = float(pbr.baseColorFactor[3]);
        }
        m.metallic = float(pbr.metallicFactor);
        m.roughness = float(pbr.roughnessFactor);
        if (src.emissiveFactor.size() == 3) {
            for (int c = 0; c < 3; ++c) m.emission[c] = float(src.emissiveFactor[c]);
        }
        auto add_texture = [&](const char* slot, int index) {
            std::string name = TextureName(model, index, embedded, path.stem().string());
            if (name.empty()) {
                if (index >= 0) {
                    warnings.Add(
                        "textures neither in a file nor embedded as PNG/JPEG (colour used)",
                        fmt::format("{} material {} {}", file, m.name, slot));
                }
                return;
            }
            // A missing or unreadable file is reported once, by the texture conversion
            // (texture_convert.h).
            m.textures[slot] = name;
        };
        add_texture("baseColorTexture", pbr.baseColorTexture.index);
        add_texture("metallicRoughnessTexture", pbr.metallicRoughnessTexture.index);
        add_texture("normalTexture", src.normalTexture.index);
        add_texture("emissiveTexture", src.emissiveTexture.index);
        add_texture("occlusionTexture", src.occlusionTexture.index);
        // alphaMode MASK (glTF 2.0 §3.9.4): cut out where base-colour alpha x baseColorFactor alpha
        // is below alphaCutoff. The renderer reads the alpha from "alphaMask", the base-colour
        // image kept as data.
        if (src.alphaMode == "MASK") {
            m.alpha_cutoff = float(src.alphaCutoff);
            add_texture("alphaMask", pbr.baseColorTexture.index);
        }
        materials.push_back(std::move(m));
    }
    uint32_t default_material = uint32_t(materials.size());
    bool default_used = false;

    GltfReader reader(model, file);
    std::vector<IndexedMesh> meshes;
    // Iterative walk of the scene graph (a malformed file could nest deeply), guarding against
    // cycles.
    std::vector<std::pair<int, Mat4>> stack;
    std::vector<int> visits(model.nodes.size(), 0);
    int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (!model.scenes.empty() && size_t(scene) < model.scenes.size()) {
        for (int n : model.scenes[scene].nodes) stack.push_back({n, Identity()});
    } else {
        for (size_t n = 0; n < model.nodes.size(); ++n) stack.push_back({int(n), Identity()});
    }
    while (!stack.empty()) {
        auto [node_index, parent] = stack.back();
        stack.pop_back();
        if (node_index < 0 || size_t(node_index) >= model.nodes.size()) {
            return InvalidArgumentError("{}: node {} out of range [0, {})", file, node_index,
                                        model.nodes.size());
        }
        if (++visits[node_index] > 1000) {
            return InvalidArgumentError(
                "{}: node {} reached more than 1000 times: the node graph has a cycle", file,
                node_index);
        }
        const tinygltf::Node& node = model.nodes[node_index];
        Mat4 world = Mul(parent, NodeMatrix(node));
        for (int child : node.children) stack.push_back({child, world});
        if (node.mesh < 0) continue;
        if (size_t(node.mesh) >= model.meshes.size()) {
            return InvalidArgumentError("{}: node {} names mesh {}, out of range", file, node_index,
                                        node.mesh);
        }
        NormalMatrix normal_matrix = MakeNormalMatrix(world);
        const tinygltf::Mesh& mesh = model.meshes[node.mesh];
        for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
            const tinygltf::Primitive& prim = mesh.primitives[pi];
            std::string where = fmt::format("{} mesh {} primitive {}", file, node.mesh, pi);
            int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN) {
                warnings.Add("glTF primitives that are points or lines skipped", where);
                continue;
            }
            auto pos_it = prim.attributes.find("POSITION");
            if (pos_it == prim.attributes.end()) {
                warnings.Add("glTF primitives without POSITION skipped", where);
                continue;
            }
            IndexedMesh out;
            out.where = where;
            NAVE_ASSIGN_OR_RETURN(std::vector<float> pos, reader.ReadFloats(pos_it->second, 3));
            out.positions.resize(pos.size() / 3);
            for (size_t v = 0; v < out.positions.size(); ++v) {
                out.positions[v] =
                    TransformPoint(world, Vec3f(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]));
            }
            if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
                NAVE_ASSIGN_OR_RETURN(std::vector<float> nrm, reader.ReadFloats(it->second, 3));
                if (nrm.size() == pos.size()) {
                    out.normals.resize(out.positions.size());
                    for (size_t v = 0; v < out.normals.size(); ++v) {
                        out.normals[v] = TransformNormal(
                            normal_matrix, Vec3f(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
                    }
                }
            }
            if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
                NAVE_ASSIGN_OR_RETURN(std::vector<float> uv, reader.ReadFloats(it->second, 2));
                if (uv.size() / 2 == out.positions.size()) {
                    out.uvs.resize(out.positions.size());
                    for (size_t v = 0; v < out.uvs.size(); ++v)
                        out.uvs[v] = {uv[2 * v], uv[2 * v + 1]};
                }
            }
            std::vector<uint32_t> idx;
            if (prim.indices >= 0) {
                NAVE_ASSIGN_OR_RETURN(idx, reader.ReadIndices(prim.indices));
            } else {
                idx.resize(out.positions.size());
                for (size_t v = 0; v < idx.size(); ++v) idx[v] = uint32_t(v);
            }
            if (mode == TINYGLTF_MODE_TRIANGLES) {
                out.indices = std::move(idx);
                out.indices.resize(out.indices.size() / 3 * 3);
            } else {
                for (size_t k = 2; k < idx.size(); ++k) {
                    if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
                        out.indices.insert(out.indices.end(), {idx[0], idx[k - 1], idx[k]});
                    } else if (k % 2 == 0) {
                        out.indices.insert(out.indices.end(), {idx[k - 2], idx[k - 1], idx[k]});
                    } else {
                        out.indices.insert(out.indices.end(), {idx[k - 1], idx[k - 2], idx[k]});
                    }
                }
            }
            // A negative determinant mirrors the mesh: swap two corners to keep counter-clockwise
            // fronts.
            if (normal_matrix.flips) {
                for (size_t t = 0; t + 2 < out.indices.size(); t += 3)
                    std::swap(out.indices[t + 1], out.indices[t + 2]);
            }
            if (prim.material >= 0 && size_t(prim.material) < materials.size()) {
                out.material = uint32_t(prim.material);
            } else {
                out.material = default_material;
                default_used = true;
            }
            meshes.push_back(std::move(out));
        }
    }
    if (default_used) {
        store::MaterialRecord m;
        m.name = "default";
        materials.push_back(m);
    }
    // The embedded images some material uses, under the names TextureName gave them.
    std::vector<std::pair<std::string, std::string>> images;
    for (const auto& [index, bytes] : embedded) {
        std::string ext = ImageExtension(bytes);
        if (ext.empty()) continue;
        std::string name = fmt::format("{}.image{}.{}", path.stem().string(), index, ext);
        bool used =
            std::any_of(materials.begin(), materials.end(), [&](const store::MaterialRecord& m) {
                return std::any_of(m.textures.begin(), m.textures.end(),
                                   [&](const auto& t) { return t.second == name; });
            });
        if (used) images.emplace_back(std::move(name), bytes);
    }
    auto source = std::make_unique<IndexedMeshSource>(file, "m", std::move(meshes),
                                                      std::move(materials), std::move(warnings));
    source->SetEmbeddedImages(std::move(images));
    return std::unique_ptr<TriangleSource>(std::move(source));
}

}  // namespace nave::preprocess
