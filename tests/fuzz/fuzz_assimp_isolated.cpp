// The Assimp path as `nave preprocess` takes it: Assimp in a child process (one fork per input),
// the model sent back through a pipe. Whatever Assimp does to the child, nave must return a Status.
// The child's coverage does not reach libFuzzer, so this target is run on the corpus and the
// crashes fuzz_assimp_in_process finds rather than left to explore.

#include <pthread.h>
#include <sanitizer/common_interface_defs.h>

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/assimp_importer.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    // In the child, a sanitizer report (ASan's out-of-memory on Assimp's huge reservations, which
    // the `nave` executable sees as bad_alloc) must not run libFuzzer's death callback: it would
    // save the input as a crash of the fuzzer's own process, which only sees the child exit.
    pthread_atfork(nullptr, nullptr, [] { __sanitizer_set_death_callback(nullptr); });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const auto path = nave::fuzz::WriteInput("fuzz.off", nave::fuzz::AsView(data, size));
    nave::fuzz::Drain(nave::preprocess::OpenWithAssimp(path));
    return 0;
}
