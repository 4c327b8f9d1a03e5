#pragma once
// The input format of the Assimp fuzz targets: the first byte picks the file's extension from
// kAssimpFormats (modulo its size, so every byte value names a format and a mutated first byte
// hands the same body to another reader), the rest is the file. Assimp picks its reader by the
// extension, so one target reaches the long tail of formats `nave preprocess` sends to Assimp
// (everything but OBJ, PLY, STL and glTF, which nave reads itself).
//
// Only formats Debian's Assimp 5.2 reads from a single file are listed: a reader that opens side
// files (textures, animation or material files, the parts of a split format) would find none in
// the fuzzer's scratch directory. Each has a seed in tests/fixtures/models/assimp/ (square.off is
// in tests/fixtures/models/), and scripts/fuzz.sh reads this list to prefix each seed with its
// index: append new formats at the end, so that the existing corpora keep their meaning.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace nave::fuzz {

inline constexpr std::array<const char*, 19> kAssimpFormats = {
    "off", "3ds", "ac",  "ase", "dae", "dxf", "fbx", "lwo",  "md2", "ms3d",
    "nff", "raw", "smd", "x",   "xgl", "amf", "cob", "ogex", "x3d"};

/// The file name ("fuzz.<extension>") and the file's bytes of one fuzz input; an empty input is
/// an empty OFF file.
struct AssimpFuzzInput {
    std::string name;
    std::string_view bytes;
};

inline AssimpFuzzInput SplitAssimpFuzzInput(const uint8_t* data, size_t size) {
    if (size == 0) return {"fuzz.off", {}};
    return {std::string("fuzz.") + kAssimpFormats[data[0] % kAssimpFormats.size()],
            std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1)};
}

}  // namespace nave::fuzz
