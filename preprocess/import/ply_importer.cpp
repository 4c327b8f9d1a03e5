#include "preprocess/import/ply_importer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <optional>
#include <string>

#include "preprocess/import/file_source.h"
#include "preprocess/import/stream_reader.h"
#include "preprocess/import/text_parse.h"
#include "preprocess/import/triangle_check.h"
#include "preprocess/import/triangulate.h"

namespace nave::preprocess {
namespace {

enum class Format { kAscii, kBinaryLittle, kBinaryBig };
enum class Type : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool ParseType(std::string_view name, Type& type) {
    static constexpr std::pair<const char*, Type> kNames[] = {
        {"char", Type::kInt8},      {"int8", Type::kInt8},       {"uchar", Type::kUint8},
        {"uint8", Type::kUint8},    {"short", Type::kInt16},     {"int16", Type::kInt16},
        {"ushort", Type::kUint16},  {"uint16", Type::kUint16},   {"int", Type::kInt32},
        {"int32", Type::kInt32},    {"uint", Type::kUint32},     {"uint32", Type::kUint32},
        {"float", Type::kFloat32},  {"float32", Type::kFloat32}, {"double", Type::kFloat64},
        {"float64", Type::kFloat64}};
    for (const auto& [n, t] : kNames) {
        if (name == n) {
            type = t;
            return true;
        }
    }
    return false;
}

size_t TypeSize(Type t) {
    switch (t) {
        case Type::kInt8:
        case Type::kUint8:
            return 1;
        case Type::kInt16:
        case Type::kUint16:
            return 2;
        case Type::kInt32:
        case Type::kUint32:
        case Type::kFloat32:
            return 4;
        case Type::kFloat64:
            return 8;
    }
    return 0;
}

struct Property {
    std::string name;
    Type type = Type::kFloat32;
    bool is_list = false;
    Type count_type = Type::kUint8;
};

struct Element {
    std::string name;
    uint64_t count = 0;
    std::vector<Property> properties;
};

// Which vertex property feeds which slot: x y z nx ny nz u v.
constexpr int kSlotCount = 8;
int VertexSlot(const std::string& name) {
    static constexpr std::pair<const char*, int> kNames[] = {
        {"x", 0},  {"y", 1}, {"z", 2},         {"nx", 3},        {"ny", 4},
        {"nz", 5}, {"u", 6}, {"s", 6},         {"texture_u", 6}, {"texture_s", 6},
        {"v", 7},  {"t", 7}, {"texture_v", 7}, {"texture_t", 7}};
    for (const auto& [n, s] : kNames) {
        if (name == n) return s;
    }
    return -1;
}

class PlySource final : public FileSourceWithVertices {
  public:
    PlySource(StreamReader reader, Format format, std::vector<Element> elements)
        : FileSourceWithVertices(std::move(reader)),
          format_(format),
          elements_(std::move(elements)) {
        store::MaterialRecord m;
        m.name = "default";
        materials_.push_back(m);
    }

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override {
        batch.clear();
        while (batch.size() < max_triangles && element_ < elements_.size()) {
            const Element& e = elements_[element_];
            if (record_ == e.count) {
                ++element_;
                record_ = 0;
                continue;
            }
            if (e.name == "vertex") {
                NAVE_RETURN_IF_ERROR(ReadVertices(e));
            } else if (e.name == "face" || e.name == "tristrips") {
                if (!vertices_read_) {
                    return UnsupportedError(
                        "{}: element '{}' comes before 'vertex': nave streams faces and "
                        "needs the vertices first",
                        reader_.path().string(), e.name);
                }
                while (record_ < e.count && batch.size() < max_triangles) {
                    NAVE_RETURN_IF_ERROR(ReadFaceRecord(e, e.name == "tristrips", batch));
                    ++record_;
                }
            } else if (e.properties.empty()) {
                // Records of no properties take no bytes: skipped at once, whatever their count
                // (a damaged count of 10^18 would otherwise loop for ever).
                record_ = e.count;
            } else {
                for (; record_ < e.count; ++record_) NAVE_RETURN_IF_ERROR(SkipRecord(e));
            }
        }
        if (batch.empty() && !finished_) {
            finished_ = true;
            if (triangles_ == 0) {
                return InvalidArgumentError(
                    "{}: no faces: expected a 'face' or 'tristrips' element with "
                    "vertex_indices",
                    reader_.path().string());
            }
        }
        return !batch.empty();
    }

  private:
    std::string Where() const {
        return format_ == Format::kAscii ? reader_.Where() : reader_.WhereOffset();
    }

    StatusOr<std::string_view> AsciiToken() {
        while (true) {
            std::string_view token = NextToken(line_rest_);
            if (!token.empty()) return token;
            std::string_view line;
            NAVE_ASSIGN_OR_RETURN(bool more, reader_.NextLine(line));
            if (!more) {
                return DataLossError(
                    "{}: truncated: expected more values for element '{}' record {} of {}",
                    reader_.Where(), elements_[element_].name, record_, elements_[element_].count);
            }
            line_rest_ = line;
        }
    }

    StatusOr<double> ReadValue(Type type) {
        if (format_ == Format::kAscii) {
            NAVE_ASSIGN_OR_RETURN(std::string_view token, AsciiToken());
            if (type == Type::kFloat32 || type == Type::kFloat64) {
                float f = 0;
                if (!ParseFloat(token, f)) {
                    return InvalidArgumentError("{}: expected a number, found '{}'",
                                                reader_.Where(), token);
                }
                return double(f);
            }
            int64_t i = 0;
            if (!ParseInt(token, i)) {
                return InvalidArgumentError("{}: expected an integer, found '{}'", reader_.Where(),
                                            token);
            }
            return double(i);
        }
        unsigned char bytes[8];
        size_t size = TypeSize(type);
        NAVE_RETURN_IF_ERROR(reader_.ReadBytes(bytes, size));
        bool swap = (format_ == Format::kBinaryBig) != (std::endian::native == std::endian::big);
        if (swap) {
            for (size_t i = 0; i < size / 2; ++i) std::swap(bytes[i], bytes[size - 1 - i]);
        }
        switch (type) {
            case Type::kInt8:
                return double(int8_t(bytes[0]));
            case Type::kUint8:
                return double(bytes[0]);
            case Type::kInt16: {
                int16_t v;
                std::memcpy(&v, bytes, 2);
                return double(v);
            }
            case Type::kUint16: {
                uint16_t v;
                std::memcpy(&v, bytes, 2);
                return double(v);
            }
            case Type::kInt32: {
                int32_t v;
                std::memcpy(&v, bytes, 4);
                return double(v);
            }
            case Type::kUint32: {
                uint32_t v;
                std::memcpy(&v, bytes, 4);
                return double(v);
            }
            case Type::kFloat32: {
                float v;
                std::memcpy(&v, bytes, 4);
                return double(v);
            }
            case Type::kFloat64: {
                double v;
                std::memcpy(&v, bytes, 8);
                return v;
            }
        }
        return 0.0;
    }

    StatusOr<uint64_t> ReadListCount(const Property& p) {
        NAVE_ASSIGN_OR_RETURN(double count, ReadValue(p.count_type));
        if (count < 0 || count > 1e9) {
            return InvalidArgumentError("{}: list '{}' has count {}: expected 0..1e9", Where(),
                                        p.name, count);
        }
        return uint64_t(count);
    }

    // The fewest bytes one record of `e` can take: its binary sizes (a list, its count alone), or
    // in ASCII a digit and a separator per value. At least 1.
    size_t MinRecordBytes(const Element& e) const {
        size_t bytes = 0;
        for (const Property& p : e.properties) {
            bytes += format_ == Format::kAscii ? 2 : TypeSize(p.is_list ? p.count_type : p.type);
        }
        return std::max<size_t>(bytes, 1);
    }

    Status SkipRecord(const Element& e) {
        for (const Property& p : e.properties) {
            uint64_t n = 1;
            if (p.is_list) {
                NAVE_ASSIGN_OR_RETURN(n, ReadListCount(p));
            }
            for (uint64_t i = 0; i < n; ++i) NAVE_RETURN_IF_ERROR(ReadValue(p.type).status());
        }
        if (format_ == Format::kAscii) line_rest_ = {};
        return Status::Ok();
    }

    Status ReadVertices(const Element& e) {
        std::vector<int> slots;
        bool has[kSlotCount] = {};
        for (const Property& p : e.properties) {
            int s = p.is_list ? -1 : VertexSlot(p.name);
            slots.push_back(s);
            if (s >= 0) has[s] = true;
        }
        if (!has[0] || !has[1] || !has[2]) {
            return InvalidArgumentError("{}: element 'vertex' lacks x, y or z properties",
                                        reader_.path().string());
        }
        bool normals = has[3] && has[4] && has[5];
        bool uvs = has[6] && has[7];
        // Room for as many vertices as the rest of the file can hold, not for what a damaged count
        // claims: the vectors still grow if the count was right and the estimate short.
        const uint64_t fit =
            (reader_.file_size() - std::min(reader_.file_size(), reader_.offset())) /
            MinRecordBytes(e);
        const size_t expected = size_t(std::min(e.count, fit));
        positions_.reserve(expected);
        if (normals) normals_.reserve(expected);
        if (uvs) uvs_.reserve(expected);
        for (; record_ < e.count; ++record_) {
            double v[kSlotCount] = {};
            for (size_t k = 0; k < e.properties.size(); ++k) {
                const Property& p = e.properties[k];
                if (p.is_list) {
                    NAVE_ASSIGN_OR_RETURN(uint64_t n, ReadListCount(p));
                    for (uint64_t i = 0; i < n; ++i)
                        NAVE_RETURN_IF_ERROR(ReadValue(p.type).status());
                    continue;
                }
                NAVE_ASSIGN_OR_RETURN(double value, ReadValue(p.type));
                if (slots[k] >= 0) v[slots[k]] = value;
            }
            if (format_ == Format::kAscii) line_rest_ = {};
            positions_.push_back(Vec3f(float(v[0]), float(v[1]), float(v[2])));
            if (normals) normals_.push_back(Vec3f(float(v[3]), float(v[4]), float(v[5])));
            if (uvs) uvs_.push_back({float(v[6]), float(v[7])});
        }
        vertices_read_ = true;
        return Status::Ok();
    }

    Status EmitTriangle(int64_t a, int64_t b, int64_t c, std::vector<Triangle>& batch,
                        const std::string& where) {
        Triangle t;
        int64_t idx[3] = {a, b, c};
        t.has_normals = !normals_.empty();
        t.has_uvs = !uvs_.empty();
        for (int j = 0; j < 3; ++j) {
            t.p[j] = positions_[idx[j]];
            if (t.has_normals) t.n[j] = normals_[idx[j]];
            if (t.has_uvs) t.uv[j] = uvs_[idx[j]];
        }
        if (AcceptTriangle(t, warnings_, where)) {
            batch.push_back(t);
            ++triangles_;
        }
        return Status::Ok();
    }

    Status ReadFaceRecord(const Element& e, bool strips, std::vector<Triangle>& batch) {
        std::string where = Where();
        if (format_ == Format::kAscii) {
            // Records are one per line: read the next line now so that errors name it.
            std::string_view line;
            NAVE_ASSIGN_OR_RETURN(bool more, reader_.NextLine(line));
            if (!more) {
                return DataLossError("{}: truncated: expected {} '{}' records, found {}",
                                     reader_.path().string(), e.count, e.name, record_);
            }
            line_rest_ = line;
            where = reader_.Where();
        }
        bool found = false;
        for (const Property& p : e.properties) {
            bool is_indices = p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
            uint64_t n = 1;
            if (p.is_list) {
                NAVE_ASSIGN_OR_RETURN(n, ReadListCount(p));
            }
            if (!is_indices || found) {
                for (uint64_t i = 0; i < n; ++i) NAVE_RETURN_IF_ERROR(ReadValue(p.type).status());
                continue;
            }
            found = true;
            indices_.clear();
            for (uint64_t i = 0; i < n; ++i) {
                NAVE_ASSIGN_OR_RETURN(double value, ReadValue(p.type));
                int64_t index = int64_t(value);
                if (strips && index == -1) {
                    indices_.push_back(-1);
                    continue;
                }
                if (index < 0 || index >= int64_t(positions_.size())) {
                    return InvalidArgumentError("{}: {} {} vertex index {} out of range [0, {})",
                                                where, e.name, record_, index, positions_.size());
                }
                indices_.push_back(index);
            }
        }
        if (format_ == Format::kAscii && !Trim(line_rest_).empty()) {
            warnings_.Add("extra values at the end of PLY records ignored", where);
        }
        line_rest_ = {};
        if (!found) {
            return InvalidArgumentError("{}: element '{}' has no 'vertex_indices' list property",
                                        reader_.path().string(), e.name);
        }
        if (!strips) {
            if (indices_.size() < 3) {
                warnings_.Add("faces with fewer than 3 vertices skipped", where);
                return Status::Ok();
            }
            polygon_.clear();
            for (int64_t i : indices_) polygon_.push_back(positions_[i]);
            fan_.clear();
            TriangulatePolygon(polygon_, fan_);
            for (const auto& tri : fan_) {
                NAVE_RETURN_IF_ERROR(EmitTriangle(indices_[tri[0]], indices_[tri[1]],
                                                  indices_[tri[2]], batch, where));
            }
            return Status::Ok();
        }
        // Triangle strips: triangle i of a run is (i, i+1, i+2), every other one flipped to keep
        // the winding; -1 restarts a run. Triangles with a repeated vertex join runs on purpose and
        // are dropped silently.
        size_t run_start = 0;
        for (size_t i = 0; i < indices_.size(); ++i) {
            if (indices_[i] == -1) {
                run_start = i + 1;
                continue;
            }
            if (i < run_start + 2) continue;
            int64_t a = indices_[i - 2], b = indices_[i - 1], c = indices_[i];
            if (a == b || b == c || a == c) continue;
            if ((i - run_start) % 2 == 1) std::swap(a, b);
            NAVE_RETURN_IF_ERROR(EmitTriangle(a, b, c, batch, where));
        }
        return Status::Ok();
    }

    Format format_;
    std::vector<Element> elements_;
    size_t element_ = 0;
    uint64_t record_ = 0;
    std::string_view line_rest_;
    bool vertices_read_ = false;
    bool finished_ = false;
    uint64_t triangles_ = 0;
    std::vector<int64_t> indices_;
    std::vector<Vec3f> polygon_;
    std::vector<std::array<uint32_t, 3>> fan_;
};

}  // namespace

StatusOr<std::unique_ptr<TriangleSource>> OpenPly(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(StreamReader reader, StreamReader::Open(path));
    std::string_view line;
    NAVE_ASSIGN_OR_RETURN(bool more, reader.NextLine(line));
    if (!more || Trim(line) != "ply") {
        return InvalidArgumentError(
            "{}:1: expected 'ply' as the first line, found '{}'", path.string(),
            more ? std::string(line.substr(0, 32)) : std::string("end of file"));
    }
    std::optional<Format> format;
    std::vector<Element> elements;
    while (true) {
        NAVE_ASSIGN_OR_RETURN(more, reader.NextLine(line));
        if (!more) return DataLossError("{}: header ends before 'end_header'", reader.Where());
        std::string_view rest = line;
        std::string_view keyword = NextToken(rest);
        if (keyword == "end_header") break;
        if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
        if (keyword == "format") {
            std::string_view f = NextToken(rest);
            if (f == "ascii")
                format = Format::kAscii;
            else if (f == "binary_little_endian")
                format = Format::kBinaryLittle;
            else if (f == "binary_big_endian")
                format = Format::kBinaryBig;
            else
                return UnsupportedError(
                    "{}: format '{}': expected ascii, binary_little_endian or "
                    "binary_big_endian",
                    reader.Where(), f);
        } else if (keyword == "element") {
            Element e;
            e.name = std::string(NextToken(rest));
            int64_t count = 0;
            if (!ParseInt(NextToken(rest), count) || count < 0) {
                return InvalidArgumentError("{}: 'element {}' needs a non-negative count",
                                            reader.Where(), e.name);
            }
            e.count = uint64_t(count);
            elements.push_back(std::move(e));
        } else if (keyword == "property") {
            if (elements.empty())
                return InvalidArgumentError("{}: 'property' before any 'element'", reader.Where());
            Property p;
            std::string_view type = NextToken(rest);
            if (type == "list") {
                p.is_list = true;
                if (!ParseType(NextToken(rest), p.count_type) || p.count_type == Type::kFloat32 ||
                    p.count_type == Type::kFloat64) {
                    return InvalidArgumentError("{}: list count type: expected an integer type",
                                                reader.Where());
                }
                type = NextToken(rest);
            }
            if (!ParseType(type, p.type)) {
                return InvalidArgumentError(
                    "{}: unknown property type '{}': expected char, uchar, short, ushort, "
                    "int, uint, float, double",
                    reader.Where(), type);
            }
            p.name = std::string(NextToken(rest));
            elements.back().properties.push_back(std::move(p));
        } else {
            return InvalidArgumentError("{}: unknown header line '{}'", reader.Where(),
                                        std::string(line.substr(0, 40)));
        }
    }
    if (!format) return InvalidArgumentError("{}: header has no 'format' line", path.string());
    return std::unique_ptr<TriangleSource>(
        new PlySource(std::move(reader), *format, std::move(elements)));
}

}  // namespace nave::preprocess
