#include "preprocess/import/obj_importer.h"

#include <array>
#include <string>
#include <unordered_map>

#include "preprocess/import/file_source.h"
#include "preprocess/import/mtl_parser.h"
#include "preprocess/import/stream_reader.h"
#include "preprocess/import/text_parse.h"
#include "preprocess/import/triangle_check.h"
#include "preprocess/import/triangulate.h"

namespace nave::preprocess {
namespace {

struct Corner {
    int64_t v = -1, vt = -1, vn = -1;  // 0-based, -1 when absent
};

class ObjSource final : public FileSourceWithVertices {
  public:
    explicit ObjSource(StreamReader reader) : FileSourceWithVertices(std::move(reader)) {}

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override {
        batch.clear();
        std::string_view line;
        while (batch.size() < max_triangles) {
            NAVE_ASSIGN_OR_RETURN(bool more, reader_.NextLine(line));
            if (!more) {
                if (reader_.line_number() == 0 && !empty_reported_) {
                    empty_reported_ = true;
                    return InvalidArgumentError("{}: empty file: expected OBJ statements (v, f...)",
                                                reader_.path().string());
                }
                break;
            }
            NAVE_RETURN_IF_ERROR(ParseLine(line, batch));
        }
        if (batch.empty() && !finished_) {
            finished_ = true;
            if (triangles_ == 0) {
                return InvalidArgumentError(
                    "{}: no faces found ({} lines, {} vertices): expected 'f' lines",
                    reader_.path().string(), reader_.line_number(), positions_.size());
            }
        }
        return !batch.empty();
    }

  private:
    Status ParseVec(std::string_view rest, float* out, int count, std::string_view keyword) {
        for (int i = 0; i < count; ++i) {
            std::string_view token = NextToken(rest);
            if (token.empty() && keyword == "vt" && i > 0) {  // "vt u" is legal: v = 0
                out[i] = 0.f;
                continue;
            }
            if (!ParseFloat(token, out[i])) {
                return InvalidArgumentError("{}: '{}' expects {} numbers, found '{}' as number {}",
                                            reader_.Where(), keyword, count, token, i + 1);
            }
        }
        return Status::Ok();
    }

    StatusOr<int64_t> ResolveIndex(std::string_view token, size_t count, const char* what) {
        int64_t i = 0;
        if (!ParseInt(token, i)) {
            return InvalidArgumentError("{}: face {} index '{}' is not an integer", reader_.Where(),
                                        what, token);
        }
        if (i == 0) {
            return InvalidArgumentError(
                "{}: face {} index 0: OBJ indices start at 1 (or are negative)", reader_.Where(),
                what);
        }
        int64_t resolved = i > 0 ? i - 1 : int64_t(count) + i;
        if (resolved < 0 || resolved >= int64_t(count)) {
            return InvalidArgumentError(
                "{}: face {} index {} out of range: {} defined so far (valid 1..{} or -1..-{})",
                reader_.Where(), what, i, count, count, count);
        }
        return resolved;
    }

    Status ParseFace(std::string_view rest, std::vector<Triangle>& batch) {
        corners_.clear();
        std::string_view token;
        while (!(token = NextToken(rest)).empty()) {
            Corner c;
            size_t s1 = token.find('/');
            std::string_view v = token.substr(0, s1);
            NAVE_ASSIGN_OR_RETURN(c.v, ResolveIndex(v, positions_.size(), "vertex"));
            if (s1 != std::string_view::npos) {
                std::string_view tail = token.substr(s1 + 1);
                size_t s2 = tail.find('/');
                std::string_view vt = tail.substr(0, s2);
                if (!vt.empty()) {
                    NAVE_ASSIGN_OR_RETURN(c.vt, ResolveIndex(vt, uvs_.size(), "texture"));
                }
                if (s2 != std::string_view::npos) {
                    std::string_view vn = tail.substr(s2 + 1);
                    if (!vn.empty()) {
                        NAVE_ASSIGN_OR_RETURN(c.vn, ResolveIndex(vn, normals_.size(), "normal"));
                    }
                }
            }
            corners_.push_back(c);
        }
        if (corners_.size() < 3) {
            warnings_.Add("faces with fewer than 3 vertices skipped", reader_.Where());
            return Status::Ok();
        }
        uint32_t material = CurrentMaterial();
        polygon_.clear();
        for (const Corner& c : corners_) polygon_.push_back(positions_[c.v]);
        fan_.clear();
        TriangulatePolygon(polygon_, fan_);
        for (const auto& tri : fan_) {
            const Corner* c[3] = {&corners_[tri[0]], &corners_[tri[1]], &corners_[tri[2]]};
            Triangle t;
            t.material = material;
            t.has_normals = c[0]->vn >= 0 && c[1]->vn >= 0 && c[2]->vn >= 0;
            t.has_uvs = c[0]->vt >= 0 && c[1]->vt >= 0 && c[2]->vt >= 0;
            for (int j = 0; j < 3; ++j) {
                t.p[j] = positions_[c[j]->v];
                if (t.has_normals) t.n[j] = normals_[c[j]->vn];
                if (t.has_uvs) t.uv[j] = uvs_[c[j]->vt];
            }
            if (!AcceptTriangle(t, warnings_, reader_.Where())) continue;
            batch.push_back(t);
            ++triangles_;
        }
        return Status::Ok();
    }

    uint32_t CurrentMaterial() {
        if (current_material_ < 0) current_material_ = MaterialIndex("default", nullptr);
        return uint32_t(current_material_);
    }

    int64_t MaterialIndex(const std::string& name, const store::MaterialRecord* record) {
        auto it = material_index_.find(name);
        if (it != material_index_.end()) return it->second;
        store::MaterialRecord m;
        if (record != nullptr) m = *record;
        m.name = name;
        materials_.push_back(m);
        material_index_[name] = int64_t(materials_.size() - 1);
        return int64_t(materials_.size() - 1);
    }

    Status ParseLine(std::string_view line, std::vector<Triangle>& batch) {
        std::string_view rest = line;
        std::string_view keyword = NextToken(rest);
        if (keyword.empty() || keyword[0] == '#') return Status::Ok();
        if (keyword == "v") {
            Vec3f p;
            NAVE_RETURN_IF_ERROR(
                ParseVec(rest, &p.x, 3, keyword));  // an optional 4th (w or colour) ignored
            positions_.push_back(p);
        } else if (keyword == "vt") {
            std::array<float, 2> uv;
            NAVE_RETURN_IF_ERROR(ParseVec(rest, uv.data(), 2, keyword));
            uvs_.push_back(uv);
        } else if (keyword == "vn") {
            Vec3f n;
            NAVE_RETURN_IF_ERROR(ParseVec(rest, &n.x, 3, keyword));
            normals_.push_back(n);
        } else if (keyword == "f") {
            NAVE_RETURN_IF_ERROR(ParseFace(rest, batch));
        } else if (keyword == "usemtl") {
            std::string name(Trim(rest));
            auto lib = library_.find(name);
            if (lib == library_.end() && material_index_.find(name) == material_index_.end()) {
                warnings_.Add("materials used but defined in no MTL (default colour used)",
                              reader_.Where() + " " + name);
            }
            current_material_ = MaterialIndex(name, lib == library_.end() ? nullptr : &lib->second);
        } else if (keyword == "mtllib") {
            std::string_view file;
            while (!(file = NextToken(rest)).empty()) {
                std::filesystem::path mtl = reader_.path().parent_path() / std::string(file);
                std::error_code ec;
                if (!std::filesystem::exists(mtl, ec)) {
                    warnings_.Add("missing MTL files (default materials used)",
                                  reader_.Where() + " " + std::string(file));
                    continue;
                }
                NAVE_ASSIGN_OR_RETURN(auto records, ParseMtl(mtl, warnings_));
                for (auto& r : records) library_.emplace(r.name, r);
            }
        } else if (keyword == "g" || keyword == "o" || keyword == "s" || keyword == "l" ||
                   keyword == "p" || keyword == "vp" || keyword == "cstype" ||
                   keyword == "usemap") {
            // Groups, objects, smoothing groups, lines and points carry no triangles.
        } else {
            if (line.find('\0') != std::string_view::npos || reader_.line_number() == 1) {
                return InvalidArgumentError(
                    "{}: '{}' is not an OBJ statement: expected v, vt, vn, f, usemtl...",
                    reader_.Where(), std::string(keyword.substr(0, 32)));
            }
            warnings_.Add("unknown OBJ statements ignored", reader_.Where());
        }
        return Status::Ok();
    }

    std::vector<Corner> corners_;
    std::vector<Vec3f> polygon_;
    std::vector<std::array<uint32_t, 3>> fan_;
    std::unordered_map<std::string, int64_t> material_index_;
    std::unordered_map<std::string, store::MaterialRecord> library_;
    int64_t current_material_ = -1;
    uint64_t triangles_ = 0;
    bool finished_ = false;
    bool empty_reported_ = false;
};

}  // namespace

StatusOr<std::unique_ptr<TriangleSource>> OpenObj(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(StreamReader reader, StreamReader::Open(path));
    return std::unique_ptr<TriangleSource>(new ObjSource(std::move(reader)));
}

}  // namespace nave::preprocess
