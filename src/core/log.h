#pragma once
// Logging for nave's tools: messages go to stderr, one line each, so that stdout stays clean for
// --json. A thin layer over spdlog so that no other file includes it.

#include <fmt/format.h>

#include <string>

namespace nave::log {

enum class Level { kDebug, kInfo, kWarning, kError, kOff };

/// Sets the lowest level printed (default kInfo). Thread-safe.
void SetLevel(Level level);
Level GetLevel();
void Write(Level level, const std::string& message);

template <typename... Args>
void Debug(fmt::format_string<Args...> f, Args&&... args) {
    if (GetLevel() <= Level::kDebug)
        Write(Level::kDebug, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void Info(fmt::format_string<Args...> f, Args&&... args) {
    if (GetLevel() <= Level::kInfo)
        Write(Level::kInfo, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void Warning(fmt::format_string<Args...> f, Args&&... args) {
    if (GetLevel() <= Level::kWarning)
        Write(Level::kWarning, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void Error(fmt::format_string<Args...> f, Args&&... args) {
    if (GetLevel() <= Level::kError)
        Write(Level::kError, fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace nave::log
