// The Assimp path as `nave preprocess` takes it: Assimp in a child process (one fork per input),
// the model sent back through a pipe. Whatever Assimp does to the child, nave must return a Status.
// The child's coverage does not reach libFuzzer, so this target is run on the corpus and the
// crashes fuzz_assimp_in_process finds rather than left to explore.

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/assimp_importer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto path = nave::fuzz::WriteInput("fuzz.off", nave::fuzz::AsView(data, size));
    nave::fuzz::Drain(nave::preprocess::OpenWithAssimp(path));
    return 0;
}
