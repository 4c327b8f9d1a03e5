// `nave`: one executable, one subcommand per tool. Exit codes: 0 success, 1 bad data or failed
// work, 2 bad usage (unknown option, invalid argument), 130 interrupted.

#include <malloc.h>

#include <csignal>
#include <cstdio>

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

}  // namespace

int main(int argc, char** argv) {
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
