#pragma once
// Small helpers for the commands' --json output (written by hand: the documents are flat and
// small).

#include <string>

namespace nave::cli {

/// `s` as a JSON string literal, quotes included, with control characters escaped.
std::string JsonString(const std::string& s);

}  // namespace nave::cli
