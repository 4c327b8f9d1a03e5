// `nave`: one executable, one subcommand per tool. Exit codes: 0 success, 1 bad data or failed
// work, 2 bad usage (unknown option, invalid argument), 130 interrupted.

#include <oneapi/tbb/global_control.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "src/cli/commands.h"
#include "src/cli/distributed.h"
#include "src/core/log.h"
#include "src/core/progress.h"

/// jemalloc's settings, read when it starts (before main; MALLOC_CONF in the environment overrides
/// them). nave allocates and frees pieces of many sizes, from kilobytes to tens of megabytes
/// (Embree's BVH blocks, Draco's decoder, ray queues, brick meshes), for hours. glibc's heap kept
/// every page it ever used around holes the next piece did not fit: under `render --memory 1G` the
/// billion-triangle abbey grew to 2.2 GiB. jemalloc keeps the process within a few percent of what
/// it holds.
/// - thp:always: transparent huge pages for the heap; a 4 KiB page costs a fault on first touch (12
///   us on virtual machines, 3.2 s per GiB), and bricks and queues touch gigabytes.
/// - dirty_decay_ms:-1, muzzy_decay_ms:0: freed pages stay with jemalloc for reuse (the next brick
///   load takes them without faults) until the render's ResidentSizeGuard finds the process near
///   --memory and gives them back (core/memory.h). Returning them on a timer instead (20 s) made
///   the detail-110 abbey under --memory 2G 1.18x slower.
/// - narenas:1: one arena for all threads, so what one thread frees (an eviction) is what the next
///   load on any other reuses.
/// Measured in docs/pager.md ("Memory").
extern "C" {
// NOLINTNEXTLINE: the name jemalloc looks up
const char* malloc_conf = "thp:always,dirty_decay_ms:-1,muzzy_decay_ms:0,narenas:1";
}

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

}  // namespace

int main(int argc, char** argv) {
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
    // Global flags also after the subcommand, as users type them (nave render ... -q): options a
    // subcommand does not know fall through to here. Subcommands inherit this.
    app.fallthrough();

    nave::cli::CommandRun run;
    nave::cli::RegisterVersionCommand(app, run);
    nave::cli::RegisterInspectCommand(app, run);
    nave::cli::RegisterVerifyCommand(app, run);
    nave::cli::RegisterSunCommand(app, run);
    nave::cli::RegisterSpectrumCommand(app, run);
    nave::cli::RegisterPreprocessCommand(app, run);
    nave::cli::RegisterGenerateCommand(app, run);
    nave::cli::RegisterRenderCommand(app, run);
    nave::cli::RegisterCompareCommand(app, run);

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
    // TBB's worker threads otherwise end on their own after main returns, while exit's handlers
    // run; joining them here ends the process with one thread (LeakSanitizer's exit-time check,
    // which stops every thread, crashed on a worker ending under it).
    oneapi::tbb::task_scheduler_handle tbb_workers{oneapi::tbb::attach{}};
    nave::Status status = run();
    oneapi::tbb::finalize(tbb_workers, std::nothrow);
    if (!status.ok()) {
        const std::string rank = nave::cli::RankName();
        std::fprintf(stderr, "nave: error%s: %s\n", rank.empty() ? "" : (" on " + rank).c_str(),
                     status.ToString().c_str());
        // The other ranks of a distributed render may be waiting for this one: end them all.
        nave::cli::EndAllRanksAfterError(ExitCodeFor(status));
        return ExitCodeFor(status);
    }
    return 0;
}
