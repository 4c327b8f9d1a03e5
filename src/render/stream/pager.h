#pragma once
// The out-of-core pager: which bricks stay in memory while the ray streams are drained, under a
// budget on the bytes of resident bricks (docs/pager.md). The origin paper's policy: process the
// brick with the most rays waiting, load the next one in the background while the workers trace the
// current one, and unload a brick once its queue is nearly empty. The pager owns a loader thread;
// the scheduler thread asks it which brick to process (Pick), pins bricks through it (Acquire) and
// tells it when a batch starts (Prefetch) and ends (BatchDone). Every load and eviction of a render
// goes through the pager, so its accounting (real ResidentBrick::memory_bytes of resident bricks
// plus the estimate of the brick being loaded) never exceeds the budget.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "src/core/memory.h"
#include "src/core/status.h"
#include "src/render/bricks/brick_source.h"

namespace nave::render {

/// A brick budget that never evicts: the in-core render (no --memory), which still loads bricks in
/// the background while the workers trace.
inline constexpr uint64_t kUnlimitedBrickBudget = ~uint64_t(0);

/// Tunables of the pager; docs/pager.md has the measurements behind the defaults.
struct PagerOptions {
    /// Bytes the resident bricks may take (sum of ResidentBrick::memory_bytes, plus the estimate of
    /// a brick being loaded). `nave render --memory` gets it from RenderMemoryPlan (memory_plan.h):
    /// the budget minus what it reserves for the rest. kUnlimitedBrickBudget: in-core.
    uint64_t brick_budget_bytes = kUnlimitedBrickBudget;
    bool in_core() const { return brick_budget_bytes == kUnlimitedBrickBudget; }
    /// How loaded bricks build their BVH (applied to the brick source before anything loads).
    BvhSettings bvh;
    /// Where loads, evictions, stalls, batches and queue and residency counters are recorded
    /// (`nave render --trace`); null: nowhere. Must outlive the render.
    TraceRecorder* trace = nullptr;
    /// Load the next bricks in background threads while the workers trace the current one.
    bool prefetch = true;
    /// Background loader threads (with prefetch): how many bricks may load at once beside the
    /// tracing. Each load is one thread (read, decode, BVH build); two keep a 2-core machine busy
    /// when the workers stall, and share the cores with tracing otherwise.
    int loaders = 2;
    /// A resident brick with fewer rays waiting than this counts as nearly empty: a prefetch may
    /// evict it. (Loads the scheduler cannot avoid evict whatever is unpinned, emptiest first.)
    size_t nearly_empty_rays = 4096;
    /// Process the fullest resident brick instead of loading the fullest brick when the resident
    /// one has at least this fraction of the fullest brick's rays waiting (0: drain resident bricks
    /// before any load; above 1: always the fullest brick, as in-core).
    double prefer_resident = 0;
    /// Among bricks evictable alike, which goes first: the least recently used, or the one that
    /// has taken the fewest rays so far (busy bricks, like the floor in view, stay).
    enum class Evict { kLru, kTraffic };
    Evict evict = Evict::kLru;
    /// The next wave of camera paths (or photons) is generated once no more than this fraction of a
    /// wave's paths are still waiting, so that its rays join the previous wave's tail (0: waves do
    /// not overlap).
    double wave_overlap = 0.5;
    /// Under a budget, keep each decoded brick on disk after its first load, so that reloads skip
    /// the Draco decode (BrickCache, docs/pager.md "Reloads").
    bool brick_cache = true;
    /// Bytes the brick cache may take on disk; 0: half the free space of spill_dir when the render
    /// starts.
    uint64_t brick_cache_limit_bytes = 0;
    /// Bytes of ray queues kept in memory under a budget: beyond, the full blocks of the queues of
    /// bricks that are not resident are spilled to disk (LZ4) until half of it is left, and read
    /// back when their brick is processed (docs/pager.md, "Spilling"). 0: queues stay in memory;
    /// kAutoQueueMemory: QueueMemoryBytes of the brick budget.
    static constexpr uint64_t kAutoQueueMemory = ~uint64_t(0);
    uint64_t queue_memory_bytes = kAutoQueueMemory;
    /// Where spill files go (the brick cache, the ray queues). Empty: the current directory.
    std::filesystem::path spill_dir;
    /// Pass over the full-detail bricks a ray crosses only through empty voxels of their occupancy
    /// grids (docs/pager.md, "Rays that cross a brick's air"). kAuto, the default: where every
    /// brick's grid is known from the start (BrickSource::occupancy_known: a store of format 3.4,
    /// or meshes held in memory), so that every run, budget and rank routes rays alike. kOn: also
    /// where the grids are made as bricks first load, which depends on timing: rays then take
    /// different ways through the queues from run to run; each image is as correct, but renders
    /// are no longer reproducible bit for bit. kOff: never.
    enum class SkipAir { kAuto, kOn, kOff };
    SkipAir skip_air = SkipAir::kAuto;
    /// The whole process's memory (the user's --memory; 0: none). Before each load, when the
    /// process's resident size plus the brick's estimate would pass it, the allocator gives its
    /// free pages back (ResidentSizeGuard): freed pages are otherwise kept for the next loads to
    /// reuse.
    uint64_t memory_bytes = 0;
};

/// The tunables ParsePagerTunables accepts, for help texts and errors. Each key is the name of the
/// PagerOptions field it sets without its unit (queue_memory sets queue_memory_bytes,
/// brick_cache_limit brick_cache_limit_bytes); bvh and bvh_compact set bvh.quality and bvh.compact.
inline constexpr std::string_view kPagerTunables =
    "prefetch=on|off, loaders=N, nearly_empty_rays=RAYS, prefer_resident=FRACTION, "
    "evict=lru|traffic, wave_overlap=FRACTION, bvh=low|medium|high, bvh_compact=on|off, "
    "brick_cache=on|off, brick_cache_limit=SIZE, queue_memory=SIZE, skip_air=auto|on|off";

/// Parses "prefetch=off,nearly_empty_rays=4096,prefer_resident=0.25" (any subset, comma separated)
/// into `options`. Errors name the key or value and list the accepted keys.
Status ParsePagerTunables(std::string_view text, PagerOptions* options);

/// The smallest brick budget paging can work with: the largest brick plus, with prefetching, room
/// for the next-largest one being loaded while the largest is traced.
struct BrickBudgetMinimum {
    uint64_t min_bytes = 0;
    uint32_t largest_brick = 0;
    uint64_t largest_bytes = 0;
    uint32_t second_brick =
        0;  ///< the next-largest brick (prefetch room); equal to largest if one brick
    uint64_t second_bytes = 0;
    uint64_t total_bytes = 0;  ///< all bricks resident at once (the in-core size)
    /// The coarsest level of every brick that has levels (KeptResident): never evicted when they
    /// take at most half the budget (KeepsCoarseLevels), so that the rays with wide footprints,
    /// most of those past the first bounce, never wait for a load; otherwise as many of them as
    /// half the budget holds (KeptLevels), the rest paged like any brick.
    uint64_t kept_bytes = 0;

    /// "its largest brick, brick 12, takes 40.1 MiB (42049536 bytes) when resident[, and
    /// prefetching needs room for the next-largest, brick 3 (38.0 MiB)]": why a budget is too
    /// small, for the refusals of the pager and of `nave render --memory`.
    std::string DescribeLargest(bool prefetch) const;
};
/// The minimum budget: the largest brick and, with prefetching, the next.
/// Bricks here are the source's slots (a brick at a level of detail).
BrickBudgetMinimum MinimumBrickBudget(const BrickSource& source, bool prefetch);
/// Whether the pager keeps slot `slot` resident once loaded: the coarsest level of a brick that
/// has coarser levels than its full mesh (docs/pager.md, "Levels of detail").
bool KeptResident(const BrickSource& source, uint32_t slot);
/// Whether a pager with `brick_budget_bytes` keeps the coarsest levels resident: when they take
/// at most half of it, and leave room for the largest bricks.
bool KeepsCoarseLevels(const BrickBudgetMinimum& m, uint64_t brick_budget_bytes);
/// Per slot, whether the pager never evicts it once loaded: every KeptResident slot when they all
/// fit (KeepsCoarseLevels), else the smallest of them that together take at most half the budget
/// and leave room for the largest bricks.
std::vector<bool> KeptLevels(const BrickSource& source, const BrickBudgetMinimum& m,
                             uint64_t brick_budget_bytes);

/// What the pager did during one render.
struct PagerStats {
    uint64_t brick_budget_bytes = 0;  ///< 0: in-core (no --memory)
    uint64_t peak_resident_bytes =
        0;                        ///< peak of resident bricks' bytes plus the reservation of a load
    uint64_t loads = 0;           ///< bricks loaded (on demand and prefetched)
    uint64_t prefetch_loads = 0;  ///< of which by the background loader
    uint64_t reloads = 0;         ///< loads of a brick this render had loaded before
    uint64_t evictions = 0;
    uint64_t acquires = 0;         ///< bricks pinned for a batch (or for the emitters' pass)
    uint64_t resident_hits = 0;    ///< of which were already resident when asked for
    uint64_t estimate_misses = 0;  ///< loads whose real size exceeded the estimate (should stay 0)
    uint64_t memory_returns = 0;   ///< times the allocator's free pages went back near --memory
    double stall_seconds = 0;      ///< time the scheduler waited for a load while the workers idled
};

/// The pager of one render. Thread-safe as used: the scheduler thread calls Pick, Acquire, Prefetch
/// and BatchDone; the loader thread is internal; `waiting` is called from both and must be
/// thread-safe.
class Pager {
  public:
    /// Rays waiting in the queue of a brick now (thread-safe snapshot).
    using WaitingFn = std::function<size_t(uint32_t brick)>;

    /// Checks the budget against the largest bricks (a ResourceExhausted error naming the budget,
    /// the largest brick and its size, and the minimum that would work) and starts the loader
    /// thread. Bricks already resident in `source` are kept while they fit the budget and evicted
    /// otherwise.
    static StatusOr<std::unique_ptr<Pager>> Create(BrickSource& source, const PagerOptions& options,
                                                   WaitingFn waiting);
    ~Pager();
    Pager(const Pager&) = delete;
    Pager& operator=(const Pager&) = delete;

    /// The brick to process next, given every brick's waiting rays (not all zero): the fullest
    /// brick if resident, else the fullest resident brick when it has at least prefer_resident of
    /// the fullest's rays, else the fullest brick (to be loaded).
    uint32_t Pick(const std::vector<size_t>& waiting);
    /// Pins brick `id`, loading it first if needed: waits for the loader if it is loading `id`,
    /// else loads it here after evicting unpinned bricks (emptiest queue first, least recently used
    /// on ties). Load errors name the brick. ResourceExhausted if pinned bricks leave no room (a
    /// caller holding pins).
    StatusOr<BrickHandle> Acquire(uint32_t id);
    /// A batch of brick `current` starts: asks the loader to load the fullest non-resident brick
    /// other than `current` meanwhile, evicting only nearly empty bricks (waiting for a batch end
    /// if none is). `batch_rays`: rays taken from `current`'s queue for this batch (its traffic,
    /// for eviction choices).
    void Prefetch(const std::vector<size_t>& waiting, uint32_t current, size_t batch_rays);
    /// The scheduler released its pin on the batch's brick: a loader waiting for room may retry;
    /// the allocator's free pages go back if the process nears memory_bytes.
    void BatchDone();
    /// Drops brick `id` from memory if it is resident and nobody pins it (a brick this process
    /// no longer owns in a distributed render); returns whether it went.
    bool Evict(uint32_t id);
    PagerStats stats() const;
    const PagerOptions& options() const { return options_; }
    /// Per slot, whether it is never evicted once loaded (KeptLevels for this pager's budget).
    const std::vector<bool>& kept() const { return kept_; }

  private:
    enum class State : uint8_t { kAbsent, kLoading, kResident };
    Pager(BrickSource& source, const PagerOptions& options, WaitingFn waiting);
    /// Evicts resident, unpinned bricks other than `exclude` until `need` more bytes fit; with
    /// `for_prefetch_of_rays` (a prefetch, for a brick with that many rays waiting), only bricks
    /// whose queue is nearly empty, and of those a brick a prefetch loaded and nobody has traced
    /// since only if fewer rays wait for it. Returns whether they fit. Holds mutex_.
    bool MakeRoom(uint64_t need, uint32_t exclude, std::optional<size_t> for_prefetch_of_rays);
    /// Records a finished load of `id` (real size `bytes`). Holds mutex_.
    void Loaded(uint32_t id, uint64_t bytes, bool prefetched);
    void Reserve(uint32_t id, uint64_t bytes);
    /// Counts the scheduler's wait for brick `id` since `start` as stall. Holds mutex_.
    void Stalled(uint32_t id, std::chrono::steady_clock::time_point start);
    /// The fullest brick of the last Prefetch snapshot that nobody loads or claims, or kNoBrick.
    /// Holds mutex_.
    uint32_t NextPrefetchTarget() const;
    /// Whether a loader has claimed brick `id` (making room for it or loading it). Holds mutex_.
    bool Claimed(uint32_t id) const;
    void LoaderLoop(size_t index);

    BrickSource& source_;
    const PagerOptions options_;
    const WaitingFn waiting_;
    std::vector<uint64_t> estimate_;    // by brick: estimated resident bytes
    ResidentSizeGuard resident_guard_;  // memory_bytes, checked before each load and batch end

    mutable std::mutex mutex_;
    std::condition_variable loader_cv_;  // the loader waits here for requests and batch ends
    std::condition_variable loaded_cv_;  // the scheduler waits here for the loader's load to finish
    std::vector<State> state_;
    std::vector<uint64_t> bytes_;      // resident: real bytes; loading: the reserved estimate
    std::vector<uint64_t> last_used_;  // tick of the last pick or load
    std::vector<uint64_t> traffic_;    // rays taken from the brick's queue so far
    std::vector<uint32_t> load_count_;
    std::vector<bool> kept_;  // KeptResident: never evicted
    // Loaded by a loader and not acquired since: a prefetch evicts it only for a fuller brick.
    std::vector<bool> unused_prefetch_;
    uint64_t tick_ = 0;
    uint64_t committed_bytes_ = 0;
    // The last Prefetch call's view: rays waiting per brick and the brick being traced. Loaders
    // pick the fullest brick nobody else loads from it; request_epoch_ counts the calls.
    std::vector<size_t> prefetch_waiting_;
    uint32_t prefetch_current_;
    uint64_t request_epoch_ = 0;
    struct Loader {
        uint32_t target;      // brick it is making room for or loading, or kNoBrick
        bool cancel = false;  // the scheduler took over target
        std::thread thread;
    };
    std::vector<Loader> loaders_;
    uint64_t batch_epoch_ = 0;
    bool scheduler_needs_room_ = false;  // the scheduler waits for room: loaders start no load
    bool stop_ = false;
    PagerStats stats_;
    bool warned_estimate_ = false;
};

}  // namespace nave::render
