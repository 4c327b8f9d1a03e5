#include "cli/json_text.h"

#include <fmt/format.h>

namespace nave::cli {

std::string JsonString(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        switch (c) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\t':
                out += "\\t";
                break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) {
                    out += fmt::format("\\u{:04x}", int(c));
                } else {
                    out += c;
                }
        }
    }
    return out + "\"";
}

}  // namespace nave::cli
