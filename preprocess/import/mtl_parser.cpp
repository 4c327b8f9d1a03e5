#include "preprocess/import/mtl_parser.h"

#include <string>

#include "preprocess/import/stream_reader.h"
#include "preprocess/import/text_parse.h"

namespace nave::preprocess {
namespace {

Status ParseFloats(std::string_view rest, float* out, int count, const StreamReader& reader,
                   std::string_view keyword) {
    for (int i = 0; i < count; ++i) {
        std::string_view token = NextToken(rest);
        if (token.empty() && i == 1 && count == 3) {  // "Kd 0.5" means grey
            out[1] = out[2] = out[0];
            return Status::Ok();
        }
        if (!ParseFloat(token, out[i])) {
            return InvalidArgumentError("{}: '{}' expects {} numbers, found '{}'", reader.Where(),
                                        keyword, count, token);
        }
    }
    return Status::Ok();
}

}  // namespace

StatusOr<std::vector<store::MaterialRecord>> ParseMtl(const std::filesystem::path& path,
                                                      ImportWarnings& warnings) {
    NAVE_ASSIGN_OR_RETURN(StreamReader reader, StreamReader::Open(path));
    std::vector<store::MaterialRecord> materials;
    std::string_view line;
    while (true) {
        NAVE_ASSIGN_OR_RETURN(bool more, reader.NextLine(line));
        if (!more) break;
        std::string_view rest = line;
        std::string_view keyword = NextToken(rest);
        if (keyword.empty() || keyword[0] == '#') continue;
        if (keyword == "newmtl") {
            store::MaterialRecord m;
            m.name = std::string(Trim(rest));
            if (m.name.empty())
                return InvalidArgumentError("{}: 'newmtl' without a name", reader.Where());
            materials.push_back(std::move(m));
            continue;
        }
        if (materials.empty()) continue;  // statements before the first newmtl apply to nothing
        store::MaterialRecord& m = materials.back();
        if (keyword == "Kd") {
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, m.diffuse.data(), 3, reader, keyword));
        } else if (keyword == "Ks") {
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, m.specular.data(), 3, reader, keyword));
        } else if (keyword == "Ke") {
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, m.emission.data(), 3, reader, keyword));
        } else if (keyword == "Ni") {
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, &m.ior, 1, reader, keyword));
        } else if (keyword == "Ns") {
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, &m.shininess, 1, reader, keyword));
        } else if (keyword == "d") {
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, &m.opacity, 1, reader, keyword));
        } else if (keyword == "Tr") {
            float tr = 0;
            NAVE_RETURN_IF_ERROR(ParseFloats(rest, &tr, 1, reader, keyword));
            m.opacity = 1.f - tr;
        } else if (keyword.substr(0, 4) == "map_" || keyword == "bump" || keyword == "disp" ||
                   keyword == "norm") {
            // Options ("-bm 0.5") precede the file name; the name is the last token.
            std::string_view name, token;
            while (!(token = NextToken(rest)).empty()) name = token;
            if (name.empty()) continue;
            std::string texture(name);
            // A missing or unreadable file is reported once, by the texture conversion
            // (texture_convert.h).
            m.textures[std::string(keyword)] = texture;
        }
    }
    return materials;
}

}  // namespace nave::preprocess
