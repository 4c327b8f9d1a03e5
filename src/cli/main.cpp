// `nave`: one executable, one subcommand per tool. Exit codes: 0 success, 1 bad data or failed
// work, 2 bad usage (unknown option, invalid argument), 130 interrupted.

#include <malloc.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cli/commands.h"
#include "core/log.h"
#include "core/progress.h"

namespace {

int ExitCodeFor(const nave::Status& status) {
    switch (status.code()) {
        case nave::StatusCode::kOk:
            return 0;
        case nave::StatusCode::kInvalidArgument:
            return 2;
        case nave::StatusCode::kCancelled:
            return 130;
        default:
            return 1;
    }
}

/// Restarts nave with glibc's malloc backing its heap with transparent huge pages (the
/// glibc.malloc.hugetlb tunable, glibc >= 2.35, read only at process start). A fresh 4 KiB page
/// costs a fault, on virtual machines 12 us (3.2 s per GiB touched); decoded bricks and ray queues
/// touch gigabytes. Measured on the detail-110 abbey in-core: 38.5 s -> 31.3 s, 600 k -> 56 k
/// faults. A GLIBC_TUNABLES that already names the tunable is kept as it is (glibc.malloc.hugetlb=0
/// turns this off); if the restart fails, nave runs on without.
void RestartWithHugePageHeap(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    const std::string current = tunables != nullptr ? tunables : "";
    if (current.find("glibc.malloc.hugetlb") != std::string::npos) return;
    const std::string wanted =
        current.empty() ? "glibc.malloc.hugetlb=1" : current + ":glibc.malloc.hugetlb=1";
    if (::setenv("GLIBC_TUNABLES", wanted.c_str(), 1) != 0) return;
    ::execv("/proc/self/exe", argv);
    ::unsetenv("GLIBC_TUNABLES");  // execv returned: it failed; run on as we are
    if (tunables != nullptr) ::setenv("GLIBC_TUNABLES", tunables, 1);
#else
    (void)argv;
#endif
}

}  // namespace

int main(int argc, char** argv) {
    RestartWithHugePageHeap(argv);
    // Brick decoding allocates and frees large buffers all the time. With glibc's defaults each one
    // is a fresh mmap whose page faults cost more than Draco's decoding itself (measured 2-5x
    // slower in bench_store_decode); keep such buffers in the heap and return memory to the OS less
    // eagerly.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    // A write past the file size limit (ulimit -f) then fails like a full disk, with a message
    // naming the file or spill directory, instead of killing the process.
    std::signal(SIGXFSZ, SIG_IGN);
    CLI::App app{
        "nave: out-of-core spectral rendering of very large models (CAD, scans, the procedural "
        "abbey)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("nave ") + NAVE_VERSION);
    bool quiet = false, verbose = false;
    app.add_flag("-q,--quiet", quiet,
                 "Print only errors (no progress bars, no summaries on stderr)");
    app.add_flag("-v,--verbose", verbose, "Print debugging details");

    nave::cli::CommandRun run;
    nave::cli::RegisterVersionCommand(app, run);
    nave::cli::RegisterInspectCommand(app, run);
    nave::cli::RegisterVerifyCommand(app, run);
    nave::cli::RegisterSunCommand(app, run);
    nave::cli::RegisterSpectrumCommand(app, run);
    nave::cli::RegisterPreprocessCommand(app, run);
    nave::cli::RegisterGenerateCommand(app, run);
    nave::cli::RegisterRenderCommand(app, run);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    if (quiet) {
        nave::log::SetLevel(nave::log::Level::kError);
        nave::ProgressBar::SetEnabled(false);
    } else if (verbose) {
        nave::log::SetLevel(nave::log::Level::kDebug);
    }
    if (!run) return 0;
    nave::Status status = run();
    if (!status.ok()) {
        std::fprintf(stderr, "nave: error: %s\n", status.ToString().c_str());
        return ExitCodeFor(status);
    }
    return 0;
}
