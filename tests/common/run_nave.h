#pragma once
// Runs the `nave` executable (NAVE_BINARY) as a user would, for end-to-end tests of every
// subcommand.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace nave::test {

struct CommandResult {
    int exit_code =
        -1;  ///< the process's exit code; -1 if it could not start or was killed by a signal
    std::string output;  ///< what it printed: stdout, and stderr too where asked
};

enum class Streams { kStdoutOnly, kStdoutAndStderr };

/// Runs `nave ARGS` through the shell and collects its output and exit code.
inline CommandResult RunNave(const std::string& args, Streams streams = Streams::kStdoutAndStderr) {
    const std::string command = std::string(NAVE_BINARY) + " " + args +
                                (streams == Streams::kStdoutAndStderr ? " 2>&1" : " 2>/dev/null");
    CommandResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return result;
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, n);
    const int status = ::pclose(pipe);
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

}  // namespace nave::test
