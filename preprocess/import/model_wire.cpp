#include "preprocess/import/model_wire.h"

#include <fmt/format.h>

#include <cstring>
#include <type_traits>

namespace nave::preprocess {
namespace {

// Recognises the stream, and a change of layout between two builds that cannot happen today (both
// ends are one executable) but would otherwise decode as nonsense.
constexpr char kMagic[8] = {'N', 'A', 'V', 'E', 'M', 'D', 'L', '1'};

class Writer {
  public:
    template <typename T>
    void Put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
    }
    template <typename T>
    void PutArray(const std::vector<T>& v) {
        Put(uint64_t(v.size()));
        if (!v.empty())
            bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
    void PutString(const std::string& s) {
        Put(uint64_t(s.size()));
        bytes_.append(s);
    }
    std::string& bytes() { return bytes_; }

  private:
    std::string bytes_;
};

class Reader {
  public:
    Reader(std::string_view bytes, const std::string& what) : bytes_(bytes), what_(what) {}

    template <typename T>
    Status Get(T* v) {
        static_assert(std::is_trivially_copyable_v<T>);
        NAVE_RETURN_IF_ERROR(Need(sizeof(T), 1, "a value"));
        std::memcpy(v, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return Status::Ok();
    }
    // An array is a count, then the elements: the count is checked against the bytes left before
    // the vector is sized, so a damaged count cannot ask for terabytes.
    template <typename T>
    Status GetArray(std::vector<T>* v, const char* what) {
        uint64_t n = 0;
        NAVE_RETURN_IF_ERROR(Get(&n));
        NAVE_RETURN_IF_ERROR(Need(sizeof(T), n, what));
        v->resize(size_t(n));
        if (n > 0) std::memcpy(v->data(), bytes_.data() + pos_, size_t(n) * sizeof(T));
        pos_ += size_t(n) * sizeof(T);
        return Status::Ok();
    }
    Status GetString(std::string* s, const char* what) {
        uint64_t n = 0;
        NAVE_RETURN_IF_ERROR(Get(&n));
        NAVE_RETURN_IF_ERROR(Need(1, n, what));
        s->assign(bytes_.data() + pos_, size_t(n));
        pos_ += size_t(n);
        return Status::Ok();
    }
    // A count of records each at least `min_bytes` long.
    Status GetCount(uint64_t* n, size_t min_bytes, const char* what) {
        NAVE_RETURN_IF_ERROR(Get(n));
        return Need(min_bytes, *n, what);
    }
    Status Error(const std::string& problem) const {
        return DataLossError("{}: the model sent by the importer process is damaged @{}: {}", what_,
                             pos_, problem);
    }
    size_t pos() const { return pos_; }
    size_t remaining() const { return bytes_.size() - pos_; }

  private:
    Status Need(size_t element_bytes, uint64_t count, const char* what) const {
        if (count > remaining() / element_bytes) {
            return Error(fmt::format("{} x {} bytes of {} but only {} bytes remain", count,
                                     element_bytes, what, remaining()));
        }
        return Status::Ok();
    }
    std::string_view bytes_;
    const std::string& what_;
    size_t pos_ = 0;
};

void PutMaterial(Writer& w, const store::MaterialRecord& m) {
    w.PutString(m.name);
    w.Put(m.diffuse);
    w.Put(m.specular);
    w.Put(m.emission);
    w.Put(m.ior);
    w.Put(m.opacity);
    w.Put(m.shininess);
    w.Put(m.metallic);
    w.Put(m.roughness);
    w.Put(m.alpha_cutoff);
    w.Put(uint64_t(m.textures.size()));
    for (const auto& [slot, file] : m.textures) {
        w.PutString(slot);
        w.PutString(file);
    }
}

Status GetMaterial(Reader& r, store::MaterialRecord* m) {
    NAVE_RETURN_IF_ERROR(r.GetString(&m->name, "material name"));
    NAVE_RETURN_IF_ERROR(r.Get(&m->diffuse));
    NAVE_RETURN_IF_ERROR(r.Get(&m->specular));
    NAVE_RETURN_IF_ERROR(r.Get(&m->emission));
    NAVE_RETURN_IF_ERROR(r.Get(&m->ior));
    NAVE_RETURN_IF_ERROR(r.Get(&m->opacity));
    NAVE_RETURN_IF_ERROR(r.Get(&m->shininess));
    NAVE_RETURN_IF_ERROR(r.Get(&m->metallic));
    NAVE_RETURN_IF_ERROR(r.Get(&m->roughness));
    NAVE_RETURN_IF_ERROR(r.Get(&m->alpha_cutoff));
    uint64_t textures = 0;
    NAVE_RETURN_IF_ERROR(r.GetCount(&textures, 16, "texture slots"));
    for (uint64_t t = 0; t < textures; ++t) {
        std::string slot, file;
        NAVE_RETURN_IF_ERROR(r.GetString(&slot, "texture slot"));
        NAVE_RETURN_IF_ERROR(r.GetString(&file, "texture file"));
        m->textures[slot] = file;
    }
    return Status::Ok();
}

}  // namespace

std::string EncodeImportedModel(const ImportedModel& model) {
    Writer w;
    w.bytes().append(kMagic, sizeof(kMagic));
    w.Put(uint64_t(model.materials.size()));
    for (const store::MaterialRecord& m : model.materials) PutMaterial(w, m);
    w.Put(uint64_t(model.meshes.size()));
    for (const IndexedMesh& mesh : model.meshes) {
        w.PutString(mesh.where);
        w.Put(mesh.material);
        w.PutArray(mesh.positions);
        w.PutArray(mesh.normals);
        w.PutArray(mesh.uvs);
        w.PutArray(mesh.indices);
    }
    return std::move(w.bytes());
}

StatusOr<ImportedModel> DecodeImportedModel(std::string_view bytes, const std::string& what) {
    Reader r(bytes, what);
    if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
        return r.Error("it does not start with the model stream's magic");
    char magic[sizeof(kMagic)];
    NAVE_RETURN_IF_ERROR(r.Get(&magic));
    ImportedModel model;
    uint64_t materials = 0;
    // A material takes at least its name's length, 12 floats and a texture count: 64 bytes.
    NAVE_RETURN_IF_ERROR(r.GetCount(&materials, 64, "materials"));
    model.materials.resize(size_t(materials));
    for (store::MaterialRecord& m : model.materials) NAVE_RETURN_IF_ERROR(GetMaterial(r, &m));
    uint64_t meshes = 0;
    // A mesh takes at least its name's length, its material and four array counts: 44 bytes.
    NAVE_RETURN_IF_ERROR(r.GetCount(&meshes, 44, "meshes"));
    model.meshes.resize(size_t(meshes));
    for (IndexedMesh& mesh : model.meshes) {
        NAVE_RETURN_IF_ERROR(r.GetString(&mesh.where, "mesh name"));
        NAVE_RETURN_IF_ERROR(r.Get(&mesh.material));
        NAVE_RETURN_IF_ERROR(r.GetArray(&mesh.positions, "positions"));
        NAVE_RETURN_IF_ERROR(r.GetArray(&mesh.normals, "normals"));
        NAVE_RETURN_IF_ERROR(r.GetArray(&mesh.uvs, "texture coordinates"));
        NAVE_RETURN_IF_ERROR(r.GetArray(&mesh.indices, "indices"));
        // IndexedMeshSource looks normals and uvs up by position index: they must match or be
        // absent.
        if ((!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) ||
            (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())) {
            return r.Error(fmt::format("{}: {} positions but {} normals and {} uvs", mesh.where,
                                       mesh.positions.size(), mesh.normals.size(),
                                       mesh.uvs.size()));
        }
        if (mesh.indices.size() % 3 != 0) {
            return r.Error(fmt::format("{}: {} indices, not a multiple of 3", mesh.where,
                                       mesh.indices.size()));
        }
    }
    if (r.remaining() != 0) return r.Error(fmt::format("{} bytes follow the model", r.remaining()));
    return model;
}

}  // namespace nave::preprocess
