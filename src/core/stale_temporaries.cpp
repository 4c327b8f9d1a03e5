#include "src/core/stale_temporaries.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>

namespace nave {
namespace {

/// Reads the decimal digits at the front of `text` into `value`; returns how many there were.
size_t Digits(std::string_view text, long* value) {
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *value);
    if (ec != std::errc()) return 0;
    return size_t(end - text.data());
}

}  // namespace

long TemporaryOwner(std::string_view name, std::string_view prefix, std::string_view suffix) {
    if (!name.starts_with(prefix) || !name.ends_with(suffix)) return -1;
    if (name.size() < prefix.size() + suffix.size()) return -1;
    std::string_view middle =
        name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    long pid = -1, n = -1;
    const size_t pid_digits = Digits(middle, &pid);
    if (pid_digits == 0 || pid_digits >= middle.size() || middle[pid_digits] != '-') return -1;
    middle.remove_prefix(pid_digits + 1);
    if (middle.empty() || middle[0] == '-' || middle[0] == '+') return -1;
    if (Digits(middle, &n) != middle.size()) return -1;
    return pid > 0 ? pid : -1;
}

bool ProcessAlive(long pid) {
    if (pid <= 0) return false;
    // Signal 0 checks existence only; EPERM means it exists under another user.
    return ::kill(pid_t(pid), 0) == 0 || errno == EPERM;
}

std::vector<std::filesystem::path> RemoveStaleTemporaries(const std::filesystem::path& dir,
                                                          std::string_view prefix,
                                                          std::string_view suffix) {
    std::vector<std::filesystem::path> removed;
    std::error_code ec;
    const std::filesystem::path where = dir.empty() ? std::filesystem::path(".") : dir;
    for (const auto& entry : std::filesystem::directory_iterator(where, ec)) {
        const long pid = TemporaryOwner(entry.path().filename().string(), prefix, suffix);
        if (pid <= 0 || pid == long(::getpid()) || ProcessAlive(pid)) continue;
        std::error_code remove_ec;
        std::filesystem::remove_all(entry.path(), remove_ec);
        if (!remove_ec) removed.push_back(entry.path());
    }
    return removed;
}

}  // namespace nave
