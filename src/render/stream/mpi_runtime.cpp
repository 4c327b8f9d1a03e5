#include "src/render/stream/mpi_runtime.h"

#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "src/render/stream/mpi_wait.h"

namespace nave::render {

StatusOr<MpiRuntime> MpiRuntime::Init(int* argc, char*** argv) {
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        return InternalError("MPI: MPI_Init_thread failed");
    }
    if (provided < MPI_THREAD_FUNNELED) {
        MPI_Finalize();
        return UnsupportedError(
            "MPI gives thread level {} where nave needs MPI_THREAD_FUNNELED ({}): its "
            "workers trace on threads while one of them calls MPI",
            provided, int(MPI_THREAD_FUNNELED));
    }
    return MpiRuntime();
}

MpiRuntime::~MpiRuntime() {
    if (active_) MPI_Finalize();
}

int MpiRuntime::rank() const {
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank;
}

int MpiRuntime::size() const {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    return size;
}

std::string MpiRuntime::host() const {
    char name[MPI_MAX_PROCESSOR_NAME];
    int length = 0;
    if (MPI_Get_processor_name(name, &length) != MPI_SUCCESS) return "unknown host";
    return std::string(name, size_t(length));
}

Status MpiStatus(int code, std::string_view call) {
    if (code == MPI_SUCCESS) return Status::Ok();
    char text[MPI_MAX_ERROR_STRING];
    int length = 0;
    if (MPI_Error_string(code, text, &length) != MPI_SUCCESS) {
        return InternalError("MPI: {} failed: code {}", call, code);
    }
    return InternalError("MPI: {} failed: {}", call, std::string_view(text, size_t(length)));
}

void MpiRuntime::AbortAll(int exit_code) {
    MPI_Abort(MPI_COMM_WORLD, exit_code);
    std::abort();  // MPI_Abort does not return; if it did, this rank still ends
}

Status WaitForRequest(MPI_Request* request, double timeout_s,
                      const std::function<Status(double waited_s)>& timed_out) {
    const auto start = std::chrono::steady_clock::now();
    for (int spins = 0;; ++spins) {
        int done = 0;
        NAVE_RETURN_IF_ERROR(MpiStatus(MPI_Test(request, &done, MPI_STATUS_IGNORE), "MPI_Test"));
        if (done) return Status::Ok();
        const double waited =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (timeout_s > 0 && waited > timeout_s) return timed_out(waited);
        // The first spins answer an operation that completes at once (a collective every rank
        // has joined, a message already whole).
        if (spins > 1000) std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
}

Status WaitForCollective(MPI_Request* request, const char* what, MPI_Comm comm, double timeout_s) {
    return WaitForRequest(request, timeout_s, [&](double waited) {
        int rank = 0, size = 0;
        MPI_Comm_rank(comm, &rank);
        MPI_Comm_size(comm, &size);
        return InternalError(
            "rank {} of {} waited {:.0f} s in {} for the other ranks, and one never came: a "
            "rank has stopped or hangs (--rank-timeout sets this wait)",
            rank, size, waited, what);
    });
}

}  // namespace nave::render
