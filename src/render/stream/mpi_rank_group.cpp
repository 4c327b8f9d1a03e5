#include "src/render/stream/mpi_rank_group.h"

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "src/render/stream/mpi_runtime.h"
#include "src/render/stream/mpi_wait.h"

namespace nave::render {

struct MpiRankGroup::Comm {
    MPI_Comm comm = MPI_COMM_NULL;
};

namespace {

// Sums `values` of MPI type `type` over the ranks in place, in parts whose count fits MPI's int.
template <typename T>
Status SumInParts(MPI_Comm comm, std::span<T> values, MPI_Datatype type, double timeout_s) {
    constexpr size_t kPart = size_t(1) << 28;
    for (size_t at = 0; at < values.size(); at += kPart) {
        const int count = int(std::min(kPart, values.size() - at));
        MPI_Request request = MPI_REQUEST_NULL;
        NAVE_RETURN_IF_ERROR(MpiStatus(
            MPI_Iallreduce(MPI_IN_PLACE, values.data() + at, count, type, MPI_SUM, comm, &request),
            "MPI_Iallreduce"));
        NAVE_RETURN_IF_ERROR(WaitForCollective(&request, "a sum", comm, timeout_s));
    }
    return Status::Ok();
}

// The int counts and offsets of parts of `sizes` bytes laid end to end, as MPI's v-collectives take
// them; returns the bytes in all. Errors: more than an int can count (`what` names the bytes).
StatusOr<int64_t> CountsAndOffsets(const std::vector<int64_t>& sizes, std::vector<int>* counts,
                                   std::vector<int>* offsets, const char* what) {
    counts->resize(sizes.size());
    offsets->resize(sizes.size());
    int64_t total = 0;
    for (size_t r = 0; r < sizes.size(); ++r) {
        (*offsets)[r] = int(total);
        (*counts)[r] = int(sizes[r]);
        total += sizes[r];
        if (total > int64_t(std::numeric_limits<int>::max())) {
            return ResourceExhaustedError(
                "MPI: {} bytes {} between {} ranks, more than the {} one collective can count",
                total, what, sizes.size(), std::numeric_limits<int>::max());
        }
    }
    return total;
}

}  // namespace

StatusOr<std::unique_ptr<MpiRankGroup>> MpiRankGroup::Create(const MpiExchangeOptions& options) {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) return InternalError("MPI: the rank group needs MPI initialized first");
    std::unique_ptr<MpiRankGroup> group(new MpiRankGroup());
    group->comm_ = std::make_unique<Comm>();
    NAVE_RETURN_IF_ERROR(
        MpiStatus(MPI_Comm_dup(MPI_COMM_WORLD, &group->comm_->comm), "MPI_Comm_dup"));
    MPI_Comm_set_errhandler(group->comm_->comm, MPI_ERRORS_RETURN);
    MPI_Comm_rank(group->comm_->comm, &group->rank_);
    MPI_Comm_size(group->comm_->comm, &group->size_);
    group->options_ = options;
    return group;
}

MpiRankGroup::~MpiRankGroup() {
    if (comm_ && comm_->comm != MPI_COMM_NULL) MPI_Comm_free(&comm_->comm);
}

StatusOr<std::unique_ptr<RayExchange>> MpiRankGroup::MakeExchange(std::vector<int> owners,
                                                                  BrickQueues<RayRecord>& queues) {
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<MpiRayExchange> exchange,
                          MpiRayExchange::Create(std::move(owners), queues, options_));
    return std::unique_ptr<RayExchange>(std::move(exchange));
}

Status MpiRankGroup::SumEverywhere(std::span<double> values) {
    return SumInParts(comm_->comm, values, MPI_DOUBLE, options_.stall_timeout_s);
}
Status MpiRankGroup::SumEverywhere(std::span<float> values) {
    return SumInParts(comm_->comm, values, MPI_FLOAT, options_.stall_timeout_s);
}
Status MpiRankGroup::SumEverywhere(std::span<uint32_t> values) {
    return SumInParts(comm_->comm, values, MPI_UINT32_T, options_.stall_timeout_s);
}
Status MpiRankGroup::SumEverywhere(std::span<uint64_t> values) {
    return SumInParts(comm_->comm, values, MPI_UINT64_T, options_.stall_timeout_s);
}

StatusOr<std::vector<std::byte>> MpiRankGroup::GatherEverywhere(std::span<const std::byte> mine) {
    const int64_t size = int64_t(mine.size());
    const auto ranks = static_cast<size_t>(size_);
    std::vector<int64_t> sizes(ranks, 0);
    MPI_Request request = MPI_REQUEST_NULL;
    NAVE_RETURN_IF_ERROR(MpiStatus(
        MPI_Iallgather(&size, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, comm_->comm, &request),
        "MPI_Iallgather"));
    NAVE_RETURN_IF_ERROR(
        WaitForCollective(&request, "a gather", comm_->comm, options_.stall_timeout_s));
    std::vector<int> counts, offsets;
    NAVE_ASSIGN_OR_RETURN(const int64_t total,
                          CountsAndOffsets(sizes, &counts, &offsets, "to gather"));
    std::vector<std::byte> all(static_cast<size_t>(total));
    NAVE_RETURN_IF_ERROR(
        MpiStatus(MPI_Iallgatherv(mine.data(), int(mine.size()), MPI_BYTE, all.data(),
                                  counts.data(), offsets.data(), MPI_BYTE, comm_->comm, &request),
                  "MPI_Iallgatherv"));
    NAVE_RETURN_IF_ERROR(
        WaitForCollective(&request, "a gather", comm_->comm, options_.stall_timeout_s));
    return all;
}

StatusOr<std::vector<std::byte>> MpiRankGroup::SendToEach(
    std::span<const std::vector<std::byte>> to_rank) {
    const auto ranks = static_cast<size_t>(size_);
    if (to_rank.size() != ranks) {
        return InternalError("MPI: {} parts to send to {} ranks", to_rank.size(), size_);
    }
    // How much each sends each: then the bytes, with int counts and offsets on both sides.
    std::vector<int64_t> send_sizes(ranks), receive_sizes(ranks, 0);
    for (size_t r = 0; r < ranks; ++r) send_sizes[r] = int64_t(to_rank[r].size());
    MPI_Request request = MPI_REQUEST_NULL;
    NAVE_RETURN_IF_ERROR(
        MpiStatus(MPI_Ialltoall(send_sizes.data(), 1, MPI_INT64_T, receive_sizes.data(), 1,
                                MPI_INT64_T, comm_->comm, &request),
                  "MPI_Ialltoall"));
    NAVE_RETURN_IF_ERROR(
        WaitForCollective(&request, "an exchange", comm_->comm, options_.stall_timeout_s));
    std::vector<int> send_counts, send_offsets, receive_counts, receive_offsets;
    NAVE_ASSIGN_OR_RETURN(const int64_t sent,
                          CountsAndOffsets(send_sizes, &send_counts, &send_offsets, "to send"));
    NAVE_ASSIGN_OR_RETURN(const int64_t received, CountsAndOffsets(receive_sizes, &receive_counts,
                                                                   &receive_offsets, "to receive"));
    std::vector<std::byte> out(static_cast<size_t>(sent)), in(static_cast<size_t>(received));
    for (size_t r = 0; r < ranks; ++r) {
        std::copy(to_rank[r].begin(), to_rank[r].end(),
                  out.begin() + std::ptrdiff_t(send_offsets[r]));
    }
    NAVE_RETURN_IF_ERROR(
        MpiStatus(MPI_Ialltoallv(out.data(), send_counts.data(), send_offsets.data(), MPI_BYTE,
                                 in.data(), receive_counts.data(), receive_offsets.data(), MPI_BYTE,
                                 comm_->comm, &request),
                  "MPI_Ialltoallv"));
    NAVE_RETURN_IF_ERROR(
        WaitForCollective(&request, "an exchange", comm_->comm, options_.stall_timeout_s));
    return in;
}

}  // namespace nave::render
