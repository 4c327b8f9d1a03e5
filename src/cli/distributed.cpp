#include "src/cli/distributed.h"

#include <cstdlib>
#include <memory>

#include "src/core/log.h"
#include "src/core/progress.h"

#ifdef NAVE_HAVE_MPI
#include "src/render/stream/mpi_rank_group.h"
#include "src/render/stream/mpi_runtime.h"
#endif

namespace nave::cli {
namespace {

#ifdef NAVE_HAVE_MPI
// MPI's lifetime: from the first JoinRanks to the end of the process.
struct Distributed {
    std::unique_ptr<render::MpiRuntime> runtime;
    std::unique_ptr<render::MpiRankGroup> group;
    std::string host;
    ~Distributed() {
        group.reset();  // its communicator before MPI_Finalize
        runtime.reset();
    }
};
Distributed& State() {
    static Distributed state;
    return state;
}
#endif

}  // namespace

int LaunchedRanks() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
        if (const char* value = std::getenv(name)) {
            const int n = std::atoi(value);
            if (n > 0) return n;
        }
    }
    return 1;
}

StatusOr<render::RankGroup*> JoinRanks(const RankOptions& options) {
    if (LaunchedRanks() <= 1) return static_cast<render::RankGroup*>(nullptr);
#ifdef NAVE_HAVE_MPI
    Distributed& state = State();
    if (!state.group) {
        NAVE_ASSIGN_OR_RETURN(render::MpiRuntime runtime,
                              render::MpiRuntime::Init(nullptr, nullptr));
        state.runtime = std::make_unique<render::MpiRuntime>(std::move(runtime));
        state.host = state.runtime->host();
        render::MpiExchangeOptions exchange;
        exchange.stall_timeout_s = options.rank_timeout_s;
        exchange.pack_messages = options.pack_rays;
        exchange.coarse_levels_everywhere = options.coarse_levels_everywhere;
        NAVE_ASSIGN_OR_RETURN(state.group, render::MpiRankGroup::Create(exchange));
        // One terminal for the job: rank 0 reports progress and the summary, the others only
        // their errors (which name the rank).
        if (state.group->rank() != 0) {
            log::SetLevel(log::Level::kWarning);
            ProgressBar::SetEnabled(false);
        }
    }
    return static_cast<render::RankGroup*>(state.group.get());
#else
    (void)options;
    return UnsupportedError(
        "started by mpirun as one of {} ranks, but this nave was built without MPI: install "
        "libopenmpi-dev and openmpi-bin (scripts/setup-debian.sh does) and build again, or run "
        "nave without mpirun",
        LaunchedRanks());
#endif
}

std::string RankName() {
#ifdef NAVE_HAVE_MPI
    const Distributed& state = State();
    if (state.group) {
        return fmt::format("rank {} of {} on {}", state.group->rank(), state.group->size(),
                           state.host);
    }
#endif
    return "";
}

std::filesystem::path TracePathOfRank(const std::filesystem::path& path, int rank) {
    std::filesystem::path out = path;
    out.replace_filename(path.stem().string() + ".rank" + std::to_string(rank) +
                         path.extension().string());
    return out;
}

void EndAllRanksAfterError(int exit_code) {
#ifdef NAVE_HAVE_MPI
    if (State().group) render::MpiRuntime::AbortAll(exit_code);
#else
    (void)exit_code;
#endif
}

}  // namespace nave::cli
