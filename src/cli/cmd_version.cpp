// `nave version`: the version and the libraries nave was built with, for bug reports.
#include <cstdio>

#include "src/cli/commands.h"
#include "src/core/memory.h"

namespace nave::cli {

void RegisterVersionCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd = app.add_subcommand("version", "Print nave's version and build configuration");
    cmd->callback([&run] {
        run = [] {
            std::printf("nave %s (C++%ld, %s build)\n", NAVE_VERSION, __cplusplus / 100 % 100,
#ifdef NDEBUG
                        "release"
#else
                        "debug"
#endif
            );
            std::printf("allocator: %s\n", AllocatorName().c_str());
            return Status::Ok();
        };
    });
}

}  // namespace nave::cli
