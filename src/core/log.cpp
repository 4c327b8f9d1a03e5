#include "src/core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>

namespace nave::log {
namespace {

std::atomic<Level> g_level{Level::kInfo};

spdlog::logger& Logger() {
    static std::shared_ptr<spdlog::logger> logger = [] {
        auto l = spdlog::stderr_color_mt("nave");
        l->set_pattern("%^nave %l%$: %v");
        l->set_level(spdlog::level::trace);  // filtering happens in GetLevel()
        return l;
    }();
    return *logger;
}

}  // namespace

void SetLevel(Level level) { g_level.store(level); }
Level GetLevel() { return g_level.load(std::memory_order_relaxed); }

void Write(Level level, const std::string& message) {
    switch (level) {
        case Level::kDebug:
            Logger().debug(message);
            break;
        case Level::kInfo:
            Logger().info(message);
            break;
        case Level::kWarning:
            Logger().warn(message);
            break;
        case Level::kError:
            Logger().error(message);
            break;
        case Level::kOff:
            break;
    }
}

}  // namespace nave::log
