#include "preprocess/partition/temp_dir.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>

namespace nave::preprocess {
namespace {

std::atomic<int> g_signal{0};

void OnSignal(int sig) {
    if (g_signal.exchange(sig) != 0) {
        // Second signal: stop now, with the conventional exit code.
        _exit(128 + sig);
    }
}

bool ProcessAlive(long pid) {
    if (pid <= 0) return false;
    return ::kill(pid_t(pid), 0) == 0 || errno == EPERM;
}

// The pid in "<prefix><pid>-<n>", or -1.
long PidAfter(const std::string& name, const std::string& prefix) {
    if (name.rfind(prefix, 0) != 0) return -1;
    char* end = nullptr;
    long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
    return (end != nullptr && *end == '-') ? pid : -1;
}

}  // namespace

StatusOr<TempDir> TempDir::Create(const std::filesystem::path& parent) {
    std::error_code ec;
    std::filesystem::path dir = parent.empty() ? std::filesystem::path(".") : parent;
    if (!std::filesystem::is_directory(dir, ec)) {
        return NotFoundError("{}: temporary directory parent does not exist", dir.string());
    }
    const std::string prefix = ".nave-tmp-";
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        std::string name = entry.path().filename().string();
        long pid = PidAfter(name, prefix);
        if (pid > 0 && pid != long(::getpid()) && !ProcessAlive(pid))
            std::filesystem::remove_all(entry.path(), ec);
    }
    static std::atomic<int> counter{0};
    for (int attempt = 0; attempt < 100; ++attempt) {
        auto path = dir / (prefix + std::to_string(::getpid()) + "-" + std::to_string(counter++));
        if (std::filesystem::create_directory(path, ec)) return TempDir(path);
        if (ec)
            return IoError("{}: cannot create temporary directory: {}", path.string(),
                           ec.message());
    }
    return IoError("{}: cannot create a temporary directory", dir.string());
}

Status TempDir::Annotate(Status s) const {
    if (s.ok()) return s;
    return s.WithContext("writing temporary files in " + path_.parent_path().string() +
                         " (--temp-dir chooses where)");
}

TempDir::~TempDir() {
    if (path_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

void RemoveStaleOutputTemporaries(const std::filesystem::path& output) {
    std::error_code ec;
    std::filesystem::path dir =
        output.has_parent_path() ? output.parent_path() : std::filesystem::path(".");
    const std::string prefix = output.filename().string() + ".tmp-";
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        long pid = PidAfter(entry.path().filename().string(), prefix);
        if (pid > 0 && pid != long(::getpid()) && !ProcessAlive(pid))
            std::filesystem::remove(entry.path(), ec);
    }
}

void InstallInterruptHandlers() {
    static bool installed = false;
    if (installed) return;
    installed = true;
    struct sigaction sa {};
    sa.sa_handler = OnSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

bool Cancelled() { return g_signal.load(std::memory_order_relaxed) != 0; }

Status CheckCancelled() {
    int sig = g_signal.load(std::memory_order_relaxed);
    if (sig == 0) return Status::Ok();
    return Status(StatusCode::kCancelled, "interrupted by signal " + std::to_string(sig) +
                                              ": output and temporary files removed");
}

}  // namespace nave::preprocess
