// The Assimp path as `nave preprocess` takes it, on the formats of assimp_formats.h (the first byte
// picks the extension, as in fuzz_assimp_in_process): Assimp in a child process (one fork per
// input), the model sent back through a pipe. Whatever Assimp does to the child, nave must return a
// Status. Assimp's failed assertions abort the child here, as in `nave`.
// The child's coverage does not reach libFuzzer, so this target is run on the corpus and the
// crashes fuzz_assimp_in_process finds rather than left to explore.

#include <pthread.h>
#include <sanitizer/common_interface_defs.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>

#include "assimp_formats.h"
#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/assimp_importer.h"

namespace {

// The fuzzer's own bookkeeping must stay out of the child. A sanitizer report there (ASan's
// out-of-memory on Assimp's huge reservations, which the `nave` executable sees as bad_alloc) must
// not run libFuzzer's death callback, which would save the input as a crash of the fuzzer's
// process; and an allocation must fail before libFuzzer's malloc limit (2 GiB) would save it as an
// OOM. The child's address-space cap (core/child_process.h) cannot do that under ASan, whose shadow
// memory makes the process tens of terabytes: the hard limit set here, 2 GiB above the size at the
// fork, bounds it (the cap never raises a soft limit above the hard one).
void InChild() {
    __sanitizer_set_death_callback(nullptr);
    std::FILE* statm = std::fopen("/proc/self/statm", "r");
    if (statm == nullptr) return;
    unsigned long long pages = 0;
    const bool read = std::fscanf(statm, "%llu", &pages) == 1;
    std::fclose(statm);
    if (!read) return;
    const rlim_t limit = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGE_SIZE)) + (rlim_t(2) << 30);
    const rlimit as = {limit, limit};
    ::setrlimit(RLIMIT_AS, &as);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    pthread_atfork(nullptr, nullptr, InChild);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const nave::fuzz::AssimpFuzzInput input = nave::fuzz::SplitAssimpFuzzInput(data, size);
    const auto path = nave::fuzz::WriteInput(input.name, input.bytes);
    nave::fuzz::Drain(nave::preprocess::OpenWithAssimp(path));
    return 0;
}
