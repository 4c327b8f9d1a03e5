#include "src/core/check.h"

#include <cstdio>
#include <cstdlib>

namespace nave::detail {

CheckFailure::CheckFailure(const char* file, int line, const std::string& what) {
    stream_ << file << ":" << line << ": " << what << " ";
}

CheckFailure::~CheckFailure() {
    std::fprintf(stderr, "nave: internal error (a bug, please report it): %s\n",
                 stream_.str().c_str());
    std::fflush(stderr);
    std::abort();
}

}  // namespace nave::detail
