#pragma once
// Status and StatusOr<T>: how nave reports bad input (a malformed model, a corrupt store, a wrong
// config key). Bugs are reported by the CHECK macros in check.h instead. Only main() turns a Status
// into an exit code.

#include <fmt/format.h>

#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "src/core/check.h"

namespace nave {

enum class StatusCode {
    kOk = 0,
    kInvalidArgument,  // a bad option, config key or value given by the user
    kNotFound,         // a missing file, material, brick...
    kIoError,          // the operating system refused a read or write (full disk, permissions)
    kDataLoss,         // a corrupt or truncated file: checksum mismatch, short read
    kUnsupported,  // a valid file this version cannot read (future major version, unknown format)
    kResourceExhausted,  // a memory budget that cannot hold the work
    kCancelled,          // interrupted by the user
    kInternal,           // a library failed in a way that is not the input's fault
};

/// The name of a code, as printed in messages ("data loss", "invalid argument"...).
const char* StatusCodeName(StatusCode code);

/// A success or an error with a message that says what, where, expected vs found.
/// Cheap to copy when ok; the message is built only on failure.
class [[nodiscard]] Status {
  public:
    Status() = default;
    Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

    static Status Ok() { return Status(); }
    bool ok() const { return code_ == StatusCode::kOk; }
    StatusCode code() const { return code_; }
    const std::string& message() const { return message_; }
    /// "data loss: abbey.nave brick 12 @0x1a2b: checksum ..."
    std::string ToString() const;

    /// Returns a copy whose message is prefixed by `context` ("while reading X: ...").
    Status WithContext(const std::string& context) const;

  private:
    StatusCode code_ = StatusCode::kOk;
    std::string message_;
};

template <typename... Args>
Status InvalidArgumentError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kInvalidArgument, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
Status NotFoundError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kNotFound, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
Status IoError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kIoError, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
Status DataLossError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kDataLoss, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
Status UnsupportedError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kUnsupported, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
Status ResourceExhaustedError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kResourceExhausted, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
Status InternalError(fmt::format_string<Args...> f, Args&&... args) {
    return Status(StatusCode::kInternal, fmt::format(f, std::forward<Args>(args)...));
}

/// A value or the Status that explains why there is none.
template <typename T>
class [[nodiscard]] StatusOr {
  public:
    StatusOr(const Status& status) : status_(status) {  // NOLINT: implicit by design
        NAVE_CHECK(!status.ok()) << "StatusOr built from an ok Status without a value";
    }
    StatusOr(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design

    bool ok() const { return status_.ok(); }
    const Status& status() const { return status_; }

    T& value() & {
        CheckHasValue();
        return *value_;
    }
    const T& value() const& {
        CheckHasValue();
        return *value_;
    }
    T&& value() && {
        CheckHasValue();
        return std::move(*value_);
    }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }

  private:
    void CheckHasValue() const {
        NAVE_CHECK(value_.has_value()) << "StatusOr has no value: " << status_.ToString();
    }
    Status status_;
    std::optional<T> value_;
};

}  // namespace nave

#define NAVE_STATUS_CONCAT_INNER(a, b) a##b
#define NAVE_STATUS_CONCAT(a, b) NAVE_STATUS_CONCAT_INNER(a, b)

/// Returns the Status from the enclosing function if `expr` is not ok.
#define NAVE_RETURN_IF_ERROR(expr)                   \
    do {                                             \
        ::nave::Status nave_status_ = (expr);        \
        if (!nave_status_.ok()) return nave_status_; \
    } while (0)

/// `NAVE_ASSIGN_OR_RETURN(auto x, F());` declares x from a StatusOr or returns its error.
#define NAVE_ASSIGN_OR_RETURN(lhs, expr) \
    NAVE_ASSIGN_OR_RETURN_IMPL(NAVE_STATUS_CONCAT(nave_statusor_, __LINE__), lhs, expr)
#define NAVE_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
    auto tmp = (expr);                             \
    if (!tmp.ok()) return tmp.status();            \
    lhs = std::move(tmp).value()
