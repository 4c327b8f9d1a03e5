// `nave preprocess`: model files (or a generator) -> brick store. Placeholder until the partitioner lands.
#include "cli/commands.h"

namespace nave::cli {

void RegisterPreprocessCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd = app.add_subcommand("preprocess", "Cut models into a brick store (.nave)");
    cmd->callback([&run] { run = [] { return Status(StatusCode::kUnsupported, "not yet"); }; });
}

}  // namespace nave::cli
