#include "src/core/duration.h"

#include <charconv>
#include <cmath>
#include <string>

namespace nave {

StatusOr<double> ParseDuration(std::string_view text, std::string_view option) {
    auto error = [&] {
        return InvalidArgumentError(
            "{} {}: expected a duration such as 90s, 10m, 1.5h or 2d (a number of seconds without "
            "a unit), at least 0",
            option, text);
    };
    double value = 0;
    const char* end = text.data() + text.size();
    auto [rest, ec] = std::from_chars(text.data(), end, value);
    if (ec != std::errc() || rest == text.data() || !std::isfinite(value) || value < 0)
        return error();
    const std::string_view unit(rest, size_t(end - rest));
    double scale = 0;
    if (unit.empty() || unit == "s") {
        scale = 1;
    } else if (unit == "m") {
        scale = 60;
    } else if (unit == "h") {
        scale = 3600;
    } else if (unit == "d") {
        scale = 86400;
    } else {
        return error();
    }
    return value * scale;
}

}  // namespace nave
