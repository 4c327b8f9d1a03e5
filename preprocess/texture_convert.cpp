#include "preprocess/texture_convert.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "src/core/file.h"
#include "src/core/hash.h"
#include "src/core/log.h"
#include "src/core/progress.h"
#include "src/core/stale_temporaries.h"
#include "src/imaging/make_texture.h"

namespace nave::preprocess {

namespace {

std::filesystem::path Resolve(const std::string& name,
                              const std::vector<std::filesystem::path>& source_dirs) {
    std::filesystem::path p(name);
    std::error_code ec;
    if (p.is_absolute()) return p;
    for (const auto& dir : source_dirs)
        if (std::filesystem::exists(dir / p, ec)) return dir / p;
    return source_dirs.empty() ? p : source_dirs.front() / p;
}

struct Converted {
    std::string first_user;  // "material lion map_Kd", for warnings
    bool ok = false;
    std::string relative;  // to the store's directory
};

}  // namespace

std::filesystem::path TextureFolderFor(const std::filesystem::path& store_path) {
    return store_path.parent_path() / (store_path.filename().string() + ".textures");
}

void RemoveStaleTextureTemporaries(const std::filesystem::path& store_path) {
    const std::filesystem::path folder = TextureFolderFor(store_path);
    if (!std::filesystem::is_directory(folder)) return;
    // The extensions ConvertTextures writes.
    for (const char* extension : {".exr", ".tx"}) {
        for (const std::filesystem::path& p : RemoveStaleTemporaries(folder, ".tmp-", extension))
            log::Info("removed {}, left by an earlier nave run that was killed", p.string());
    }
}

bool IsColourTextureSlot(const std::string& slot) {
    static const std::set<std::string> kColour = {"map_Kd", "map_Ka",           "map_Ks",
                                                  "map_Ke", "baseColorTexture", "emissiveTexture"};
    return kColour.count(slot) != 0;
}

namespace {

// The checksum of a texture's source file and of how it is converted (colour or data, and this
// version of the conversion), read in pieces.
StatusOr<uint64_t> SourceChecksum(const std::filesystem::path& source, bool colour) {
    std::ifstream in(source, std::ios::binary);
    if (!in) return IoError("{}: cannot read the texture", source.string());
    StreamingChecksum64 sum;
    const std::string how = colour ? "nave texture 1: colour" : "nave texture 1: data";
    sum.Update(how.data(), how.size());
    std::vector<char> buffer(1 << 20);
    while (in) {
        in.read(buffer.data(), std::streamsize(buffer.size()));
        sum.Update(buffer.data(), size_t(in.gcount()));
    }
    if (in.bad()) return IoError("{}: cannot read the texture", source.string());
    return sum.Digest();
}

}  // namespace

StatusOr<TextureConvertStats> ConvertTextures(std::vector<store::MaterialRecord>* materials,
                                              const std::vector<std::filesystem::path>& source_dirs,
                                              const std::filesystem::path& store_path) {
    auto start = std::chrono::steady_clock::now();
    TextureConvertStats stats;
    // Distinct (source file, colour?) pairs, converted once however many slots use them.
    std::map<std::pair<std::filesystem::path, bool>, Converted> work;
    for (const store::MaterialRecord& m : *materials)
        for (const auto& [slot, name] : m.textures) {
            Converted& c = work[{Resolve(name, source_dirs), IsColourTextureSlot(slot)}];
            if (c.first_user.empty()) c.first_user = fmt::format("material {} {}", m.name, slot);
        }
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
        // Colour, and data that comes as OpenEXR (spectral maps, whose band centres live in an EXR
        // header attribute), are written as OpenEXR; other data as TIFF in its own pixel type.
        const char* extension = colour || source.extension() == ".exr" ? "exr" : "tx";
        std::filesystem::path temp =
            folder / fmt::format(".tmp-{}-{}.{}", getpid(), counter.fetch_add(1), extension);
        Status made = imaging::MakeTiledTexture(
            source, temp,
            colour ? imaging::TextureContent::kColour : imaging::TextureContent::kData);
        if (!made.ok()) {
            std::filesystem::remove(temp, ec);
            if (made.code() == StatusCode::kIoError)
                return made;  // the output side: nothing to fall back on
            stats.warnings.push_back(
                fmt::format("texture {} (used by {}); its materials use their flat value",
                            made.message(), result.first_user));
            continue;
        }
        // Named after what it was made from (its bytes are a function of those): preprocessing the
        // same model into the same place again replaces each converted texture, with the same
        // bytes, instead of adding another; the name is known before the conversion's bytes.
        NAVE_ASSIGN_OR_RETURN(uint64_t source_checksum, SourceChecksum(source, colour));
        std::error_code size_ec;
        const uint64_t bytes_written = std::filesystem::file_size(temp, size_ec);
        std::string file_name =
            fmt::format("{}{}.{}.{}", source.stem().string(), colour ? "" : ".data",
                        ChecksumHex(source_checksum), extension);
        if (Status synced = SyncFile(temp); !synced.ok()) {
            std::filesystem::remove(temp, ec);
            return synced;
        }
        std::filesystem::rename(temp, folder / file_name, ec);
        if (ec) {
            std::filesystem::remove(temp, ec);
            return IoError("{}: cannot rename from {}: {}", (folder / file_name).string(),
                           temp.string(), ec.message());
        }
        result.ok = true;
        result.relative = (folder.filename() / file_name).generic_string();
        ++stats.converted;
        stats.bytes_written += size_ec ? 0 : bytes_written;
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
