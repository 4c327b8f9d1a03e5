// glTF importer: the input is a .glb when it starts with the binary container's magic "glTF", else
// the JSON of a .gltf (its buffers as data URIs, as in the seeds).

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/gltf_importer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view input = nave::fuzz::AsView(data, size);
    const bool binary = input.substr(0, 4) == "glTF";
    const auto path = nave::fuzz::WriteInput(binary ? "fuzz.glb" : "fuzz.gltf", input);
    nave::fuzz::Drain(nave::preprocess::OpenGltf(path));
    return 0;
}
