#pragma once
// nave under mpirun (docs/distributed.md): whether this process is one rank of an MPI job, MPI's
// lifetime in the `nave` executable, and the end of the whole job when one rank fails.

#include <filesystem>
#include <string>

#include "src/core/status.h"
#include "src/render/stream/ray_exchange.h"

namespace nave::cli {

/// Ranks in the job that started this process, from the launcher's environment (Open MPI's
/// OMPI_COMM_WORLD_SIZE, or PMI_SIZE of other launchers); 1 when not started by mpirun.
int LaunchedRanks();

/// How the ranks of a job exchange rays (`nave render`'s options under mpirun).
struct RankOptions {
    /// --rank-timeout (MpiExchangeOptions::stall_timeout_s).
    double rank_timeout_s = 600;
    /// --pack-rays: messages of rays packed for the wire (MpiExchangeOptions::pack_messages).
    bool pack_rays = true;
    /// --coarse-levels-everywhere (MpiExchangeOptions::coarse_levels_everywhere).
    bool coarse_levels_everywhere = true;
};

/// The ranks of this job, MPI initialized on the first call (and finalized at exit); null when
/// this process is the only one. Errors: a job of several ranks and a nave built without MPI
/// (names what to install), MPI that cannot start.
StatusOr<render::RankGroup*> JoinRanks(const RankOptions& options = {});

/// Where a failed rank is named: "rank 2 of 4 on node7" ("" outside a distributed render).
std::string RankName();
/// Where rank `rank` of a distributed render writes the trace the user asked at `path`:
/// "render.json" -> "render.rank1.json".
std::filesystem::path TracePathOfRank(const std::filesystem::path& path, int rank);

/// Ends every rank of a distributed render after this one failed (MPI_Abort with `exit_code`): the
/// others may be waiting for its rays. Returns at once when there is no distributed render.
void EndAllRanksAfterError(int exit_code);

}  // namespace nave::cli
