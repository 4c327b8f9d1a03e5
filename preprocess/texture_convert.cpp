#include "preprocess/texture_convert.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <map>
#include <set>
#include <utility>

#include "core/color.h"
#include "core/file.h"
#include "core/hash.h"
#include "core/progress.h"

namespace nave::preprocess {

namespace {

// OpenImageIO errors end in newlines and repeat the file name; one line is kept.
std::string OneLine(std::string s) {
    for (char& c : s)
        if (c == '\n') c = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s.empty() ? "no detail from OpenImageIO" : s;
}

std::filesystem::path Resolve(const std::string& name,
                              const std::vector<std::filesystem::path>& source_dirs) {
    std::filesystem::path p(name);
    std::error_code ec;
    if (p.is_absolute()) return p;
    for (const auto& dir : source_dirs)
        if (std::filesystem::exists(dir / p, ec)) return dir / p;
    return source_dirs.empty() ? p : source_dirs.front() / p;
}

// Decodes the sRGB transfer curve (IEC 61966-2-1) of the first three channels in place; alpha and
// further channels are linear already.
void DecodeSrgb(OIIO::ImageBuf& buf) {
    const OIIO::ImageSpec& spec = buf.spec();
    int colour_channels = std::min(spec.nchannels, 3);
    std::vector<float> row(size_t(spec.width) * spec.nchannels);
    for (int y = spec.y; y < spec.y + spec.height; ++y) {
        OIIO::ROI roi(spec.x, spec.x + spec.width, y, y + 1, 0, 1, 0, spec.nchannels);
        buf.get_pixels(roi, OIIO::TypeFloat, row.data());
        for (int x = 0; x < spec.width; ++x)
            for (int c = 0; c < colour_channels; ++c) {
                float& v = row[size_t(x) * spec.nchannels + c];
                v = float(SrgbDecode(std::clamp(double(v), 0.0, 1.0)));
            }
        buf.set_pixels(roi, OIIO::TypeFloat, row.data());
    }
}

struct Converted {
    bool ok = false;
    std::string relative;  // to the store's directory
};

}  // namespace

std::filesystem::path TextureFolderFor(const std::filesystem::path& store_path) {
    return store_path.parent_path() / (store_path.filename().string() + ".textures");
}

bool IsColourTextureSlot(const std::string& slot) {
    static const std::set<std::string> kColour = {"map_Kd", "map_Ka",           "map_Ks",
                                                  "map_Ke", "baseColorTexture", "emissiveTexture"};
    return kColour.count(slot) != 0;
}

StatusOr<TextureConvertStats> ConvertTextures(std::vector<store::MaterialRecord>* materials,
                                              const std::vector<std::filesystem::path>& source_dirs,
                                              const std::filesystem::path& store_path) {
    auto start = std::chrono::steady_clock::now();
    TextureConvertStats stats;
    // Distinct (source file, colour?) pairs, converted once however many slots use them.
    std::map<std::pair<std::filesystem::path, bool>, Converted> work;
    for (const store::MaterialRecord& m : *materials)
        for (const auto& [slot, name] : m.textures)
            work[{Resolve(name, source_dirs), IsColourTextureSlot(slot)}];
    if (work.empty()) return stats;

    std::filesystem::path folder = TextureFolderFor(store_path);
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec)
        return IoError("{}: cannot create the texture folder: {}", folder.string(), ec.message());

    ProgressBar progress("textures", work.size(), "files");
    static std::atomic<int> counter{0};
    for (auto& [key, result] : work) {
        const auto& [source, colour] = key;
        progress.Add(1);
        OIIO::ImageBuf in(source.string());
        if (!std::filesystem::exists(source, ec)) {
            stats.warnings.push_back(fmt::format(
                "texture {}: no such file; its materials use their flat colour", source.string()));
            continue;
        }
        if (!in.read(0, 0, /*force=*/true, OIIO::TypeFloat)) {
            stats.warnings.push_back(
                fmt::format("texture {}: unreadable ({}); its materials use their flat colour",
                            source.string(), OneLine(in.geterror())));
            continue;
        }
        if (colour) DecodeSrgb(in);
        // Colour: half-float OpenEXR (OIIO's TIFF writer stores half as float); data: TIFF in the
        // source's pixel type. Both tiled and MIP-mapped by make_texture.
        const char* extension = colour ? "exr" : "tx";
        OIIO::ImageSpec config;
        config.format = colour ? OIIO::TypeHalf : in.nativespec().format;
        config.tile_width = config.tile_height = 64;
        config.attribute("wrapmodes", "periodic,periodic");
        config.attribute("compression", "zip");
        std::filesystem::path temp =
            folder / fmt::format(".tmp-{}-{}.{}", getpid(), counter.fetch_add(1), extension);
        if (!OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, in, temp.string(),
                                              config)) {
            std::filesystem::remove(temp, ec);
            return IoError("{}: cannot write the texture converted from {}: {}", temp.string(),
                           source.string(), OneLine(OIIO::geterror()));
        }
        NAVE_ASSIGN_OR_RETURN(std::string bytes, ReadFileToString(temp));
        std::string file_name =
            fmt::format("{}{}.{}.{}", source.stem().string(), colour ? "" : ".data",
                        ChecksumHex(Checksum64(bytes.data(), bytes.size())), extension);
        std::filesystem::rename(temp, folder / file_name, ec);
        if (ec) {
            std::filesystem::remove(temp, ec);
            return IoError("{}: cannot rename from {}: {}", (folder / file_name).string(),
                           temp.string(), ec.message());
        }
        result.ok = true;
        result.relative = (folder.filename() / file_name).generic_string();
        ++stats.converted;
        stats.bytes_written += bytes.size();
    }
    progress.Finish();

    for (store::MaterialRecord& m : *materials) {
        for (auto it = m.textures.begin(); it != m.textures.end();) {
            const Converted& c =
                work[{Resolve(it->second, source_dirs), IsColourTextureSlot(it->first)}];
            if (c.ok) {
                it->second = c.relative;
                ++stats.references;
                ++it;
            } else {
                ++stats.dropped;
                it = m.textures.erase(it);
            }
        }
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

}  // namespace nave::preprocess
