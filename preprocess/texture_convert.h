#pragma once
// Texture conversion for `nave preprocess`: every image a material references (MTL map_Kd, map_d,
// bump, norm...; glTF baseColorTexture, normalTexture, emissiveTexture,
// metallicRoughnessTexture...) becomes a tiled (64x64), MIP-mapped texture written with
// OpenImageIO's make_texture into the folder "<store file name>.textures/" beside the store, so
// that the renderer reads textures tile by tile through a capped cache. Colour slots are decoded
// from sRGB to linear and kept as half floats (so MIP levels average light, not encoded values);
// data slots (alpha, normals, roughness) keep their values and pixel type.
//
// Files are content-addressed: "<source stem>[.data].<XXH64 of the file, 16 hex digits>.<exr|tx>"
// (".data" for data slots; data from an OpenEXR source stays OpenEXR, so spectral maps keep their
// band centres), written to a temporary name and renamed, so the reference in the material table
// carries the checksum the renderer can verify (see docs/textures.md). A missing or unreadable
// texture gives one warning naming it and its slot is dropped, so the material falls back to its
// flat colour.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "src/core/status.h"
#include "store/material_record.h"

namespace nave::preprocess {

struct TextureConvertStats {
    uint64_t converted = 0;      ///< distinct (file, colour/data) conversions written
    uint64_t references = 0;     ///< material slots now pointing at a converted file
    uint64_t dropped = 0;        ///< material slots dropped (missing or unreadable file)
    uint64_t bytes_written = 0;  ///< bytes of converted texture files
    double seconds = 0;
    std::vector<std::string> warnings;  ///< one per missing or unreadable file, naming it
};

/// The folder of converted textures for `store_path`: "<store file name>.textures" beside it.
std::filesystem::path TextureFolderFor(const std::filesystem::path& store_path);

/// Removes, and logs, the temporaries ".tmp-<pid>-<n>.exr" / ".tx" that conversions of killed runs
/// left in TextureFolderFor(store_path) (those of processes still running stay).
void RemoveStaleTextureTemporaries(const std::filesystem::path& store_path);

/// True for slots whose texels are sRGB-encoded colours (map_Kd, map_Ka, map_Ks, map_Ke,
/// baseColorTexture, emissiveTexture); false for data (alpha, normals, bump, roughness...).
bool IsColourTextureSlot(const std::string& slot);

/// Converts the textures of `materials` (paths relative to one of `source_dirs`, tried in order;
/// absolute paths as they are) into TextureFolderFor(store_path) and rewrites each slot to the
/// converted file's path relative to the store's directory. Slots whose file is missing or
/// unreadable are removed, with one warning per file. Errors (Status) only for the output side:
/// the folder cannot be created or a file cannot be written.
StatusOr<TextureConvertStats> ConvertTextures(std::vector<store::MaterialRecord>* materials,
                                              const std::vector<std::filesystem::path>& source_dirs,
                                              const std::filesystem::path& store_path);

}  // namespace nave::preprocess
