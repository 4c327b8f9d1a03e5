// The Assimp path as `nave preprocess` takes it, on the formats of assimp_formats.h (the first byte
// picks the extension, as in fuzz_assimp_in_process): Assimp in a child process (one fork per
// input), the model sent back through a pipe. Whatever Assimp does to the child, nave must return a
// Status. Assimp's failed assertions abort the child here, as in `nave`.
// The child's coverage does not reach libFuzzer, so this target is run on the corpus and the
// crashes fuzz_assimp_in_process finds rather than left to explore.

#include "assimp_formats.h"
#include "drain.h"
#include "fuzz_file.h"
#include "isolated_child.h"
#include "preprocess/import/assimp_importer.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    pthread_atfork(nullptr, nullptr, nave::fuzz::LimitForkedChild);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const nave::fuzz::AssimpFuzzInput input = nave::fuzz::SplitAssimpFuzzInput(data, size);
    const auto path = nave::fuzz::WriteInput(input.name, input.bytes);
    nave::fuzz::Drain(nave::preprocess::OpenWithAssimp(path));
    return 0;
}
