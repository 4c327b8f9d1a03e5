#pragma once
// A file size limit (RLIMIT_FSIZE) for the length of a scope, with SIGXFSZ ignored: writes past it
// then fail with EFBIG, as they would with ENOSPC on a full disk. Processes started meanwhile
// inherit the limit. Tests that check what a full disk does use it.

#include <sys/resource.h>

#include <csignal>

namespace nave::test {

class ScopedFileSizeLimit {
  public:
    explicit ScopedFileSizeLimit(rlim_t bytes) {
        ok_ = ::getrlimit(RLIMIT_FSIZE, &old_) == 0;
        previous_ = std::signal(SIGXFSZ, SIG_IGN);
        struct rlimit limit = old_;
        limit.rlim_cur = bytes;
        ok_ = ok_ && ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
    }
    ~ScopedFileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &old_);
        std::signal(SIGXFSZ, previous_);
    }
    ScopedFileSizeLimit(const ScopedFileSizeLimit&) = delete;
    ScopedFileSizeLimit& operator=(const ScopedFileSizeLimit&) = delete;
    /// Whether the limit is in force.
    bool ok() const { return ok_; }

  private:
    struct rlimit old_ {};
    void (*previous_)(int) = SIG_DFL;
    bool ok_ = false;
};

}  // namespace nave::test
