#pragma once
// Durations as users type them on the command line: "90s", "10m", "1.5h", "2d" or plain seconds.

#include <string_view>

#include "src/core/status.h"

namespace nave {

/// Seconds in `text`: a non-negative number with an optional unit s, m, h or d (none: seconds).
/// Errors: InvalidArgument naming `option` and the expected form.
StatusOr<double> ParseDuration(std::string_view text, std::string_view option);

}  // namespace nave
