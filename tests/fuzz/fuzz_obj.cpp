// OBJ + MTL importer. The input is the OBJ text, then optionally a NUL byte and the text of an MTL
// library written as fuzz.mtl next to it (the seeds' `mtllib` lines name that file), so the fuzzer
// mutates both and the links between them.

#include <cstring>

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/obj_importer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view input = nave::fuzz::AsView(data, size);
    const size_t split = input.find('\0');
    const std::string_view obj = input.substr(0, split);
    const std::string_view mtl =
        split == std::string_view::npos ? std::string_view() : input.substr(split + 1);
    nave::fuzz::WriteInput("fuzz.mtl", mtl);
    nave::fuzz::Drain(nave::preprocess::OpenObj(nave::fuzz::WriteInput("fuzz.obj", obj)));
    return 0;
}
