#include "src/render/stream/mpi_rank_group.h"

#include <mpi.h>

#include <algorithm>

#include "src/render/stream/mpi_runtime.h"

namespace nave::render {

struct MpiRankGroup::Comm {
    MPI_Comm comm = MPI_COMM_NULL;
};

namespace {

// Sums `values` of MPI type `type` over the ranks in place, in parts whose count fits MPI's int.
template <typename T>
Status SumInParts(MPI_Comm comm, std::span<T> values, MPI_Datatype type) {
    constexpr size_t kPart = size_t(1) << 28;
    for (size_t at = 0; at < values.size(); at += kPart) {
        const int count = int(std::min(kPart, values.size() - at));
        NAVE_RETURN_IF_ERROR(
            MpiStatus(MPI_Allreduce(MPI_IN_PLACE, values.data() + at, count, type, MPI_SUM, comm),
                      "MPI_Allreduce"));
    }
    return Status::Ok();
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
    return SumInParts(comm_->comm, values, MPI_DOUBLE);
}
Status MpiRankGroup::SumEverywhere(std::span<float> values) {
    return SumInParts(comm_->comm, values, MPI_FLOAT);
}
Status MpiRankGroup::SumEverywhere(std::span<uint32_t> values) {
    return SumInParts(comm_->comm, values, MPI_UINT32_T);
}
Status MpiRankGroup::SumEverywhere(std::span<uint64_t> values) {
    return SumInParts(comm_->comm, values, MPI_UINT64_T);
}

}  // namespace nave::render
