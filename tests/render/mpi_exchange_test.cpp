// The ray exchange between MPI ranks (mpi_ray_exchange.h), run under mpirun with 2 and 3 ranks
// (tests/render/CMakeLists.txt). A game of rays stands in for a render: every ray hops from brick
// to brick a number of times its id decides, each hop to a brick its id and hop decide, and ends by
// adding its id to the rank it ends on; the ranks own the bricks round robin. Every ray must end
// exactly once (the sums of ids and of rays agree with the game's), every rank must stop in the
// same call, and every record sent must be received.

#include <gtest/gtest.h>
#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "src/render/stream/mpi_ray_exchange.h"
#include "src/render/stream/mpi_runtime.h"
#include "src/render/stream/ray_message.h"
#include "src/render/transport/rng.h"

namespace nave::render {
namespace {

constexpr uint32_t kBricks = 11;

// Hops that look random and are the same on every rank.
uint32_t Mix(uint32_t x) { return uint32_t(MixBits(x)); }

uint32_t NextBrick(const RayRecord& r) { return Mix(r.pixel * 31u + r.depth) % kBricks; }

struct Game {
    uint64_t rays_started = 0;  // on this rank
    uint64_t rays_ended = 0;
    uint64_t id_sum_started = 0;
    uint64_t id_sum_ended = 0;
    uint64_t hops = 0;
    uint64_t hops_kept_home = 0;  // hops into a brick every rank holds (kEveryRank)
};

// Drains this rank's queues as the scheduler would: batches of one brick at a time, each split
// between two threads that send on concurrently, progress between batches, and the exchange asked
// for more rays or the end when the queues are empty.
Status Play(MpiRayExchange& exchange, BrickQueues<RayRecord>& queues, Game* game) {
    std::vector<RayRecord> batch;
    uint64_t batches = 0;
    while (true) {
        bool any = false;
        for (uint32_t b = 0; b < kBricks; ++b) {
            if (queues.Waiting(b) == 0) continue;
            any = true;
            NAVE_RETURN_IF_ERROR(queues.Take(b, 500, &batch).status());
            // Ranks that take turns being slow, so that rays arrive at ranks that have just gone
            // idle and the rounds of the end's detection meet every order of events.
            ++batches;
            if (Mix(uint32_t(batches) * 7919u + uint32_t(exchange.rank())) % 4 == 0)
                std::this_thread::sleep_for(std::chrono::microseconds(300));
            std::atomic<uint64_t> ended{0}, id_sum{0}, hops{0}, kept_home{0};
            auto work = [&](size_t begin, size_t end) {
                std::vector<RayRecord> next;
                for (size_t i = begin; i < end; ++i) {
                    RayRecord r = batch[i];
                    if (!exchange.Owns(b)) std::abort();  // a ray in the wrong rank
                    if (r.depth == 0) {
                        ended += 1;
                        id_sum += r.pixel;
                        continue;
                    }
                    r.depth -= 1;
                    hops += 1;
                    if (exchange.Owner(NextBrick(r)) == kEveryRank) kept_home += 1;
                    exchange.Send(NextBrick(r), std::span<const RayRecord>(&r, 1));
                }
            };
            const size_t half = batch.size() / 2;
            std::thread other(work, 0, half);
            work(half, batch.size());
            other.join();
            game->rays_ended += ended;
            game->id_sum_ended += id_sum;
            game->hops += hops;
            game->hops_kept_home += kept_home;
            NAVE_RETURN_IF_ERROR(exchange.Progress());
        }
        if (any) continue;
        NAVE_ASSIGN_OR_RETURN(bool end, exchange.WaitForRaysOrEnd());
        if (end) return Status::Ok();
    }
}

// Starts `count` rays on this rank, ids spread over the ranks, each in a brick it owns or not (a
// camera ray may start anywhere: the exchange forwards it).
void StartRays(MpiRayExchange& exchange, uint32_t count, uint32_t first_id, Game* game) {
    for (uint32_t i = 0; i < count; ++i) {
        RayRecord r;
        r.pixel = first_id + uint32_t(exchange.rank()) * count + i;
        r.depth = uint16_t(Mix(r.pixel) % 13);
        game->rays_started += 1;
        game->id_sum_started += r.pixel;
        exchange.Send(Mix(r.pixel + 7) % kBricks, std::span<const RayRecord>(&r, 1));
    }
}

uint64_t SumOverRanks(uint64_t v) {
    uint64_t sum = 0;
    MPI_Allreduce(&v, &sum, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    return sum;
}

// With `everywhere`, every third brick is held by every rank (kEveryRank: a coarse level kept
// everywhere), and the rays hopping into it stay where they are.
void PlayWaves(const MpiExchangeOptions& options, int waves, bool everywhere = false) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    std::vector<int> owners(kBricks);
    for (uint32_t b = 0; b < kBricks; ++b)
        owners[b] = everywhere && b % 3 == 0 ? kEveryRank : int(b % uint32_t(size));
    BrickQueues<RayRecord> queues(kBricks);
    auto exchange = MpiRayExchange::Create(owners, queues, options);
    ASSERT_TRUE(exchange.ok()) << exchange.status().ToString();
    Game game;
    for (int wave = 0; wave < waves; ++wave) {
        StartRays(**exchange, 3000, uint32_t(wave) * 1000000u, &game);
        const Status played = Play(**exchange, queues, &game);
        ASSERT_TRUE(played.ok()) << played.ToString();
        EXPECT_EQ(queues.TotalWaiting(), 0u);
        // Every rank ended the wave in the same call: every ray of the wave has ended somewhere.
        EXPECT_EQ(SumOverRanks(game.rays_ended), SumOverRanks(game.rays_started))
            << "wave " << wave;
    }
    EXPECT_EQ(SumOverRanks(game.id_sum_ended), SumOverRanks(game.id_sum_started));
    auto total = (*exchange)->TotalCounts();
    ASSERT_TRUE(total.ok()) << total.status().ToString();
    EXPECT_EQ(total->records_sent, total->records_received);
    const uint64_t hops = SumOverRanks(game.hops), kept_home = SumOverRanks(game.hops_kept_home);
    EXPECT_EQ(kept_home > 0, everywhere);
    // A hop into a brick every rank holds never travels.
    EXPECT_LE(total->records_sent, hops + SumOverRanks(game.rays_started) - kept_home);
    if (size > 1) {
        // Most other hops cross ranks: the rays did travel.
        EXPECT_GT(total->records_sent, (hops - kept_home) / uint64_t(2 * size));
        EXPECT_GT(total->messages_sent, 0u);
    }
}

TEST(MpiExchange, EveryRayEndsOnceOverSeveralWaves) { PlayWaves(MpiExchangeOptions(), 3); }

// Messages of a few rays and one send in flight per rank: the exchange must wait for its sends to
// complete while receiving, without a deadlock between two ranks sending to each other.
// Bricks every rank holds (coarse levels kept everywhere): their rays are traced where they are,
// and still every ray ends once.
TEST(MpiExchange, BricksEveryRankHoldsKeepTheirRaysHome) {
    PlayWaves(MpiExchangeOptions(), 2, /*everywhere=*/true);
}

TEST(MpiExchange, SmallMessagesAndOneSendInFlightStillEndEveryRay) {
    MpiExchangeOptions options;
    options.message_bytes = kRayMessageHeaderBytes + kRayGroupHeaderBytes + 4 * sizeof(RayRecord);
    options.max_sends_in_flight = 1;
    PlayWaves(options, 2);
}

TEST(MpiExchange, BadOwnersAreRefused) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    BrickQueues<RayRecord> queues(3);
    auto wrong_rank = MpiRayExchange::Create({0, size, 0}, queues);
    ASSERT_FALSE(wrong_rank.ok());
    EXPECT_NE(wrong_rank.status().message().find("slot 1 owned by rank"), std::string::npos)
        << wrong_rank.status().ToString();
    EXPECT_FALSE(MpiRayExchange::Create({0, 0}, queues).ok());
    EXPECT_TRUE(MpiRayExchange::Create({0, kEveryRank, 0}, queues).ok());
    EXPECT_FALSE(MpiRayExchange::Create({0, kEveryRank - 1, 0}, queues).ok());
}

}  // namespace
}  // namespace nave::render

int main(int argc, char** argv) {
    auto mpi = nave::render::MpiRuntime::Init(&argc, &argv);
    if (!mpi.ok()) {
        fprintf(stderr, "%s\n", mpi.status().ToString().c_str());
        return 1;
    }
    ::testing::InitGoogleTest(&argc, argv);
    // Only rank 0 prints the results; every rank's failures still fail the job (its exit code).
    if (mpi->rank() != 0) {
        auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
        delete listeners.Release(listeners.default_result_printer());
    }
    return RUN_ALL_TESTS();
}
