#pragma once
// SIGINT and SIGTERM for the commands that stop cleanly, one handler for all of them: the first
// signal asks the command to stop (a render at its next pass or iteration, once the checkpoint is
// written; a preprocess by unwinding and removing its files); a second ends the process at once,
// with the conventional exit code 128 + the signal.

#include <atomic>

namespace nave::cli {

/// Installs the handlers of SIGINT and SIGTERM (once per process) and returns the flag they set:
/// the number of the first signal, 0 until one comes (PreprocessOptions::interrupt). `notice`, if
/// not null, is written to stderr when the first signal comes; it must outlive the process (a
/// string literal).
const std::atomic<int>* InstallInterruptHandlers(const char* notice = nullptr);

/// The same handlers for a render that writes checkpoints, with a notice that says so; returns a
/// flag that turns true with the first signal (SessionOptions::stop_requested).
const std::atomic<bool>* InstallRenderInterruptHandlers();

}  // namespace nave::cli
