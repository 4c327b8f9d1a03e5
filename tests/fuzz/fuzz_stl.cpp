// STL importer: the input is the whole file.

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/stl_importer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto path = nave::fuzz::WriteInput("fuzz.stl", nave::fuzz::AsView(data, size));
    nave::fuzz::Drain(nave::preprocess::OpenStl(path));
    return 0;
}
