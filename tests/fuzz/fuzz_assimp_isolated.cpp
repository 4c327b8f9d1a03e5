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

#include <csignal>
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
//
// Time too: on some inputs (an SMD file with a NUL in its node list) Assimp loops until nave's
// limit stops it, 300 s of CPU, far past libFuzzer's timeout (20 s in scripts/fuzz.sh), which
// would save the input as a hang of the fuzzer's process. The child gets kChildWallSeconds of wall
// time instead, by alarm(): SIGALRM's default action kills it and the parent reports a crash by
// signal, the same path as Assimp's own crashes (nave's time limit itself is tested in
// ChildProcess.*). 5 s, so that two runs of one input stay inside libFuzzer's timeout: it runs an
// input a second time when its allocations and frees do not balance, to look for a leak. The CPU
// limit cannot be lowered here instead: the child sets its soft and hard limits after the fork,
// and root may raise a hard one. libFuzzer's SIGALRM handler, inherited, must not run in the
// child; its timer is not inherited.
constexpr unsigned kChildWallSeconds = 5;

void InChild() {
    __sanitizer_set_death_callback(nullptr);
    std::signal(SIGALRM, SIG_DFL);
    ::alarm(kChildWallSeconds);
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
