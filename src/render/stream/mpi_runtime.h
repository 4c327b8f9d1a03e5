#pragma once
// MPI's lifetime in a nave process (docs/distributed.md): initialized once, before any exchange, at
// the thread level nave's exchange needs (MPI calls from one thread while workers trace), and
// finalized when the runtime is destroyed. Built only where MPI is found (NAVE_HAVE_MPI).

#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave::render {

class MpiRuntime {
  public:
    /// Initializes MPI (argc/argv as main got them; MPI may remove its own arguments). Errors: MPI
    /// that cannot give MPI_THREAD_FUNNELED. One per process.
    static StatusOr<MpiRuntime> Init(int* argc, char*** argv);
    MpiRuntime(MpiRuntime&& other) noexcept : active_(other.active_) { other.active_ = false; }
    MpiRuntime& operator=(MpiRuntime&&) = delete;
    /// Finalizes MPI.
    ~MpiRuntime();

    int rank() const;
    int size() const;
    /// The name of this rank's host (MPI_Get_processor_name), for messages that name a rank.
    std::string host() const;
    /// Ends every rank of the job with `exit_code` (MPI_Abort): for a rank that failed while the
    /// others may be waiting for its rays.
    [[noreturn]] static void AbortAll(int exit_code);

  private:
    MpiRuntime() = default;
    bool active_ = true;
};

/// MPI's result `code` of the call named `call` as a Status: Ok for MPI_SUCCESS, else kInternal
/// with MPI's own words for the error (on communicators set to MPI_ERRORS_RETURN).
Status MpiStatus(int code, std::string_view call);

}  // namespace nave::render
