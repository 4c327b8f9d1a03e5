#include "preprocess/import/stl_importer.h"

#include <bit>
#include <cstring>
#include <string>

#include "preprocess/import/file_source.h"
#include "preprocess/import/stream_reader.h"
#include "preprocess/import/text_parse.h"
#include "preprocess/import/triangle_check.h"

namespace nave::preprocess {
namespace {

class StlSource final : public FileSource {
  public:
    StlSource(StreamReader reader, bool binary, uint64_t binary_count)
        : FileSource(std::move(reader)), binary_(binary), binary_count_(binary_count) {
        store::MaterialRecord m;
        m.name = "default";
        materials_.push_back(m);
    }

    StatusOr<bool> Next(std::vector<Triangle>& batch, size_t max_triangles) override {
        batch.clear();
        if (binary_) {
            NAVE_RETURN_IF_ERROR(NextBinary(batch, max_triangles));
        } else {
            NAVE_RETURN_IF_ERROR(NextAscii(batch, max_triangles));
        }
        if (batch.empty() && !finished_) {
            finished_ = true;
            if (triangles_ == 0) {
                return InvalidArgumentError("{}: no usable facets ({} read)",
                                            reader_.path().string(), facets_);
            }
        }
        return !batch.empty();
    }

  private:
    void Emit(Triangle& t, std::vector<Triangle>& batch, const std::string& where) {
        ++facets_;
        if (AcceptTriangle(t, warnings_, where)) {
            batch.push_back(t);
            ++triangles_;
        }
    }

    Status NextBinary(std::vector<Triangle>& batch, size_t max_triangles) {
        unsigned char record[50];
        while (batch.size() < max_triangles && facets_ < binary_count_) {
            std::string where = reader_.WhereOffset();
            NAVE_RETURN_IF_ERROR(reader_.ReadBytes(record, 50));
            Triangle t;
            for (int j = 0; j < 3; ++j) {
                float xyz[3];
                std::memcpy(xyz, record + 12 + 12 * j, 12);
                if constexpr (std::endian::native == std::endian::big) {
                    for (float& f : xyz)
                        f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(f)));
                }
                t.p[j] = Vec3f(xyz[0], xyz[1], xyz[2]);
            }
            Emit(t, batch, where);
        }
        return Status::Ok();
    }

    Status NextAscii(std::vector<Triangle>& batch, size_t max_triangles) {
        std::string_view line;
        while (batch.size() < max_triangles) {
            NAVE_ASSIGN_OR_RETURN(bool more, reader_.NextLine(line));
            if (!more) {
                if (corner_ != 0) {
                    return DataLossError(
                        "{}: truncated inside a facet: expected 3 'vertex' lines, found {}",
                        reader_.Where(), corner_);
                }
                break;
            }
            std::string_view rest = line;
            std::string_view keyword = NextToken(rest);
            if (keyword == "vertex") {
                if (corner_ == 3) {
                    return InvalidArgumentError(
                        "{}: a 4th 'vertex' in one facet: expected 'endloop'", reader_.Where());
                }
                Vec3f& p = current_.p[corner_];
                for (int k = 0; k < 3; ++k) {
                    std::string_view token = NextToken(rest);
                    if (!ParseFloat(token, (&p.x)[k])) {
                        return InvalidArgumentError("{}: 'vertex' expects 3 numbers, found '{}'",
                                                    reader_.Where(), token);
                    }
                }
                if (corner_ == 0) facet_where_ = reader_.Where();
                ++corner_;
            } else if (keyword == "endloop" || keyword == "endfacet") {
                if (keyword == "endloop") {
                    if (corner_ != 3) {
                        return InvalidArgumentError("{}: facet with {} vertices: expected 3",
                                                    reader_.Where(), corner_);
                    }
                    Emit(current_, batch, facet_where_);
                    corner_ = 0;
                }
            } else if (keyword == "facet" || keyword == "outer" || keyword == "solid" ||
                       keyword == "endsolid" || keyword.empty()) {
                // Structure only.
            } else {
                return InvalidArgumentError(
                    "{}: '{}' is not an ASCII STL keyword: expected facet, outer loop, "
                    "vertex, endloop, endfacet",
                    reader_.Where(), std::string(keyword.substr(0, 32)));
            }
        }
        return Status::Ok();
    }

    bool binary_;
    uint64_t binary_count_;
    uint64_t facets_ = 0, triangles_ = 0;
    bool finished_ = false;
    Triangle current_;
    int corner_ = 0;
    std::string facet_where_;
};

}  // namespace

StatusOr<std::unique_ptr<TriangleSource>> OpenStl(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(StreamReader reader, StreamReader::Open(path));
    uint64_t size = reader.file_size();
    if (size == 0)
        return InvalidArgumentError("{}: empty file: expected an STL model", path.string());
    unsigned char header[84] = {};
    NAVE_ASSIGN_OR_RETURN(size_t got, reader.ReadSome(header, 84));
    uint32_t count = 0;
    std::memcpy(&count, header + 80, 4);
    if constexpr (std::endian::native == std::endian::big) count = __builtin_bswap32(count);
    bool starts_solid = got >= 5 && std::memcmp(header, "solid", 5) == 0;
    bool size_matches = got == 84 && size == 84 + 50 * uint64_t(count);
    // The size test decides: a binary STL's size is exact, and an ASCII file matching it by chance
    // would also need its bytes 80..83 to spell that count.
    if (size_matches)
        return std::unique_ptr<TriangleSource>(new StlSource(std::move(reader), true, count));
    // "solid" followed by text is ASCII; followed by binary bytes (the triangle count, a float) it
    // is a binary file of the wrong size.
    bool text_header = true;
    for (size_t i = 0; i < got; ++i) {
        unsigned char c = header[i];
        if (c < 9 || (c > 13 && c < 32) || c == 127) text_header = false;
    }
    if (starts_solid && text_header) {
        NAVE_ASSIGN_OR_RETURN(StreamReader text, StreamReader::Open(path));
        return std::unique_ptr<TriangleSource>(new StlSource(std::move(text), false, 0));
    }
    if (got < 84) {
        return DataLossError(
            "{}: {} bytes: too short for a binary STL (84-byte header) and not ASCII "
            "(no 'solid')",
            path.string(), size);
    }
    return DataLossError("{}: binary STL header says {} triangles, so {} bytes expected, found {}",
                         path.string(), count, 84 + 50 * uint64_t(count), size);
}

}  // namespace nave::preprocess
