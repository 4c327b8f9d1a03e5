#pragma once
// Each `nave` subcommand lives in its own cmd_*.cpp and registers itself here: it adds its options
// to the CLI11 app and sets `run` to the work to do once parsing succeeded. Only main() turns a
// Status into an exit code. CLI11 is expensive to compile, so it is a precompiled header of this
// target only.

#include <CLI/CLI.hpp>
#include <functional>

#include "src/core/status.h"

namespace nave::cli {

using CommandRun = std::function<Status()>;

// One line per subcommand; main.cpp calls them in this order (the order of `nave --help`).
void RegisterVersionCommand(CLI::App& app, CommandRun& run);
void RegisterInspectCommand(CLI::App& app, CommandRun& run);
void RegisterVerifyCommand(CLI::App& app, CommandRun& run);
void RegisterSunCommand(CLI::App& app, CommandRun& run);
void RegisterSpectrumCommand(CLI::App& app, CommandRun& run);
void RegisterPreprocessCommand(CLI::App& app, CommandRun& run);
void RegisterGenerateCommand(CLI::App& app, CommandRun& run);
void RegisterRenderCommand(CLI::App& app, CommandRun& run);
void RegisterCompareCommand(CLI::App& app, CommandRun& run);

}  // namespace nave::cli
