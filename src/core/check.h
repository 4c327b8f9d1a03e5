#pragma once
// Always-on assertions for bugs (never for bad input: that is a Status). A failed check prints the
// expression, both operands for the comparison forms, the source location and a streamed message,
// then aborts.
//   NAVE_CHECK(ptr != nullptr) << "brick " << id;
//   NAVE_CHECK_EQ(a.size(), b.size());

#include <sstream>
#include <string>

namespace nave::detail {

/// Collects the message of a failed check and aborts when destroyed.
class CheckFailure {
  public:
    CheckFailure(const char* file, int line, const std::string& what);
    [[noreturn]] ~CheckFailure();
    template <typename T>
    CheckFailure& operator<<(const T& v) {
        stream_ << v;
        return *this;
    }

  private:
    std::ostringstream stream_;
};

/// Lets the ternary in the macros have type void on both branches.
struct CheckVoidify {
    void operator&(const CheckFailure&) {}
};

template <typename A, typename B>
std::string FormatOperands(const char* expr, const A& a, const B& b) {
    std::ostringstream s;
    s << expr << " (" << a << " vs " << b << ")";
    return s.str();
}

}  // namespace nave::detail

#define NAVE_CHECK(cond)                      \
    (cond) ? (void)0                          \
           : ::nave::detail::CheckVoidify() & \
                 ::nave::detail::CheckFailure(__FILE__, __LINE__, "CHECK(" #cond ") failed")

#define NAVE_CHECK_OP(a, b, op)             \
    ((a)op(b))                              \
        ? (void)0                           \
        : ::nave::detail::CheckVoidify() &  \
              ::nave::detail::CheckFailure( \
                  __FILE__, __LINE__,       \
                  ::nave::detail::FormatOperands("CHECK(" #a " " #op " " #b ") failed", (a), (b)))

#define NAVE_CHECK_EQ(a, b) NAVE_CHECK_OP(a, b, ==)
#define NAVE_CHECK_NE(a, b) NAVE_CHECK_OP(a, b, !=)
#define NAVE_CHECK_LT(a, b) NAVE_CHECK_OP(a, b, <)
#define NAVE_CHECK_LE(a, b) NAVE_CHECK_OP(a, b, <=)
#define NAVE_CHECK_GT(a, b) NAVE_CHECK_OP(a, b, >)
#define NAVE_CHECK_GE(a, b) NAVE_CHECK_OP(a, b, >=)
