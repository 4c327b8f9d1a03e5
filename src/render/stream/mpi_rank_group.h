#pragma once
// The ranks of an MPI job as a RankGroup (ray_exchange.h): rays travel through MpiRayExchange, sums
// are MPI_Allreduce on a duplicate of MPI_COMM_WORLD. Built only where MPI is found
// (NAVE_HAVE_MPI); MPI must be initialized first (MpiRuntime) and stay so while the group lives.

#include <memory>

#include "src/render/stream/mpi_ray_exchange.h"
#include "src/render/stream/ray_exchange.h"

namespace nave::render {

class MpiRankGroup final : public RankGroup {
  public:
    /// Errors: MPI not initialized. Collective.
    static StatusOr<std::unique_ptr<MpiRankGroup>> Create(const MpiExchangeOptions& options = {});
    ~MpiRankGroup() override;

    int rank() const override { return rank_; }
    int size() const override { return size_; }
    bool coarse_levels_everywhere() const override { return options_.coarse_levels_everywhere; }
    StatusOr<std::unique_ptr<RayExchange>> MakeExchange(std::vector<int> owners,
                                                        BrickQueues<RayRecord>& queues) override;
    Status SumEverywhere(std::span<double> values) override;
    Status SumEverywhere(std::span<float> values) override;
    Status SumEverywhere(std::span<uint32_t> values) override;
    Status SumEverywhere(std::span<uint64_t> values) override;
    StatusOr<std::vector<std::byte>> GatherEverywhere(std::span<const std::byte> mine) override;
    StatusOr<std::vector<std::byte>> SendToEach(
        std::span<const std::vector<std::byte>> to_rank) override;

  private:
    MpiRankGroup() = default;
    struct Comm;
    std::unique_ptr<Comm> comm_;
    int rank_ = 0, size_ = 1;
    MpiExchangeOptions options_;
};

}  // namespace nave::render
