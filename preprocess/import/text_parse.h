#pragma once
// Small, allocation-free helpers for the text formats (OBJ, MTL, PLY headers, ASCII STL).

#include <charconv>
#include <cstdint>
#include <string_view>

namespace nave::preprocess {

inline bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Splits off the next whitespace-separated token; empty when none is left.
inline std::string_view NextToken(std::string_view& text) {
    size_t i = 0;
    while (i < text.size() && IsSpace(text[i])) ++i;
    size_t j = i;
    while (j < text.size() && !IsSpace(text[j])) ++j;
    std::string_view token = text.substr(i, j - i);
    text.remove_prefix(j);
    return token;
}

inline std::string_view Trim(std::string_view text) {
    while (!text.empty() && IsSpace(text.front())) text.remove_prefix(1);
    while (!text.empty() && IsSpace(text.back())) text.remove_suffix(1);
    return text;
}

/// Parses a whole token as a float ("1e-3", "-0.5", "nan" and "inf" are accepted: callers check
/// finiteness).
inline bool ParseFloat(std::string_view token, float& out) {
    if (token.empty()) return false;
    if (token.front() == '+') token.remove_prefix(1);
    auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
    return ec == std::errc() && ptr == token.data() + token.size();
}

inline bool ParseInt(std::string_view token, int64_t& out) {
    if (token.empty()) return false;
    if (token.front() == '+') token.remove_prefix(1);
    auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), out);
    return ec == std::errc() && ptr == token.data() + token.size();
}

}  // namespace nave::preprocess
