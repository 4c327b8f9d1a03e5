#include "src/cli/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <cstring>

namespace nave::cli {
namespace {

std::atomic<int> g_signal{0};     // the first signal's number
std::atomic<bool> g_stop{false};  // set with g_signal, for those that wait on a bool
std::atomic<const char*> g_notice{nullptr};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free &&
                  std::atomic<const char*>::is_always_lock_free,
              "used in a signal handler");

void OnSignal(int sig) {
    // The second signal: now, as the user insists, with the conventional exit code.
    if (g_signal.exchange(sig) != 0) _exit(128 + sig);
    g_stop.store(true);
    // write() and strlen() are async-signal-safe where the logger is not.
    if (const char* notice = g_notice.load()) {
        [[maybe_unused]] ssize_t n = ::write(STDERR_FILENO, notice, std::strlen(notice));
    }
}

}  // namespace

const std::atomic<int>* InstallInterruptHandlers(const char* notice) {
    g_notice.store(notice);
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
    return &g_signal;
}

const std::atomic<bool>* InstallRenderInterruptHandlers() {
    InstallInterruptHandlers(
        "\nnave render: stopping after this pass or iteration to write the checkpoint (signal "
        "again to stop at once)\n");
    return &g_stop;
}

}  // namespace nave::cli
