#include "src/cli/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <cstring>

namespace nave::cli {
namespace {

std::atomic<bool> g_stop{false};

void OnSignal(int sig) {
    if (g_stop.exchange(true)) _exit(128 + sig);  // the second signal: now, as the user insists
    // write() is async-signal-safe where the logger is not.
    static const char kMessage[] =
        "\nnave render: stopping after this pass or iteration to write the checkpoint (signal "
        "again to stop at once)\n";
    [[maybe_unused]] ssize_t n = ::write(STDERR_FILENO, kMessage, sizeof(kMessage) - 1);
}

}  // namespace

const std::atomic<bool>* InstallRenderInterruptHandlers() {
    static bool installed = false;
    if (!installed) {
        installed = true;
        struct sigaction sa;
        std::memset(&sa, 0, sizeof(sa));
        sa.sa_handler = OnSignal;
        sigemptyset(&sa.sa_mask);
        sigaction(SIGINT, &sa, nullptr);
        sigaction(SIGTERM, &sa, nullptr);
    }
    return &g_stop;
}

}  // namespace nave::cli
