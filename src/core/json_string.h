#pragma once
// JSON string literals for the JSON nave writes by hand (traces, --json output: flat documents).

#include <string>
#include <string_view>

namespace nave {

/// Appends `text` as a JSON string literal (RFC 8259 section 7: quote, backslash and control
/// characters escaped; other bytes, UTF-8 included, kept as they are).
void AppendJsonString(std::string& out, std::string_view text);
/// `text` as a JSON string literal, quotes included.
inline std::string JsonString(std::string_view text) {
    std::string out;
    AppendJsonString(out, text);
    return out;
}

}  // namespace nave
