#pragma once
// The targets that fuzz an importer the way `nave` runs it, in a child process
// (core/child_process.h: fuzz_assimp_isolated, fuzz_cad_isolated): what the forked child must
// change about itself for the fuzzer. Registered with pthread_atfork(nullptr, nullptr,
// LimitForkedChild) in LLVMFuzzerInitialize.

#include <pthread.h>
#include <sanitizer/common_interface_defs.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>

namespace nave::fuzz {

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

inline void LimitForkedChild() {
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

}  // namespace nave::fuzz
