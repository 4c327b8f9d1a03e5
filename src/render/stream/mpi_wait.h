#pragma once
// Waiting for a non-blocking MPI operation with the job's rank timeout (docs/distributed.md,
// "Faults"): for the MPI sources of nave_render_mpi only (it includes mpi.h).

#include <mpi.h>

#include <functional>

#include "src/core/status.h"

namespace nave::render {

/// Waits for the non-blocking operation `request`, giving the cores to other ranks while it waits
/// long; after `timeout_s` seconds (0: never) returns `timed_out(seconds waited)`, the error that
/// names what was waited for, so that the job ends instead of hanging.
Status WaitForRequest(MPI_Request* request, double timeout_s,
                      const std::function<Status(double waited_s)>& timed_out);

/// Waits for the collective `request` on `comm` (`what` names it in the message: "a sum"), giving
/// the cores to other ranks while it waits long; after `timeout_s` seconds (0: never) a rank never
/// joined, and the error names this rank and the wait, so that the job ends instead of hanging.
Status WaitForCollective(MPI_Request* request, const char* what, MPI_Comm comm, double timeout_s);

}  // namespace nave::render
