#include "src/render/stream/pager.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <charconv>
#include <chrono>

#include "src/core/log.h"
#include "src/core/memory.h"
#include "src/core/trace.h"

namespace nave::render {

namespace {

/// A pager tunable's on|off value; the error names the key.
Status ParseOnOff(std::string_view key, std::string_view value, bool* out) {
    if (value == "on" || value == "off") {
        *out = value == "on";
        return Status::Ok();
    }
    return InvalidArgumentError("pager tunable {}={}: expected on or off", key, value);
}

}  // namespace

Status ParsePagerTunables(std::string_view text, PagerOptions* options) {
    constexpr std::string_view kKeys = kPagerTunables;
    size_t pos = 0;
    while (pos <= text.size() && !text.empty()) {
        size_t comma = text.find(',', pos);
        std::string_view item = text.substr(
            pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos);
        pos = comma == std::string_view::npos ? text.size() + 1 : comma + 1;
        if (item.empty()) continue;
        size_t eq = item.find('=');
        if (eq == std::string_view::npos) {
            return InvalidArgumentError("pager tunable '{}': expected KEY=VALUE ({})", item, kKeys);
        }
        std::string_view key = item.substr(0, eq), value = item.substr(eq + 1);
        if (key == "prefetch") {
            NAVE_RETURN_IF_ERROR(ParseOnOff(key, value, &options->prefetch));
        } else if (key == "bvh") {
            if (value == "low") {
                options->bvh.quality = BvhSettings::Quality::kLow;
            } else if (value == "medium") {
                options->bvh.quality = BvhSettings::Quality::kMedium;
            } else if (value == "high") {
                options->bvh.quality = BvhSettings::Quality::kHigh;
            } else {
                return InvalidArgumentError("pager tunable bvh={}: expected low, medium or high",
                                            value);
            }
        } else if (key == "brick_cache") {
            NAVE_RETURN_IF_ERROR(ParseOnOff(key, value, &options->brick_cache));
        } else if (key == "brick_cache_limit") {
            StatusOr<uint64_t> bytes = ParseByteSize(value);
            if (!bytes.ok()) {
                return InvalidArgumentError(
                    "pager tunable brick_cache_limit={}: expected a size (8G, 500M)", value);
            }
            options->brick_cache_limit_bytes = *bytes;
        } else if (key == "queue_memory") {
            StatusOr<uint64_t> bytes = ParseByteSize(value);
            if (!bytes.ok()) {
                return InvalidArgumentError(
                    "pager tunable queue_memory={}: expected a size (64M; 0: no spilling)", value);
            }
            options->queue_memory_bytes = *bytes;
        } else if (key == "skip_air") {
            if (value == "auto") {
                options->skip_air = PagerOptions::SkipAir::kAuto;
            } else {
                bool on = false;
                NAVE_RETURN_IF_ERROR(ParseOnOff(key, value, &on));
                options->skip_air = on ? PagerOptions::SkipAir::kOn : PagerOptions::SkipAir::kOff;
            }
        } else if (key == "bvh_compact") {
            NAVE_RETURN_IF_ERROR(ParseOnOff(key, value, &options->bvh.compact));
        } else if (key == "evict") {
            if (value == "lru") {
                options->evict = PagerOptions::Evict::kLru;
            } else if (value == "traffic") {
                options->evict = PagerOptions::Evict::kTraffic;
            } else {
                return InvalidArgumentError("pager tunable evict={}: expected lru or traffic",
                                            value);
            }
        } else if (key == "nearly_empty_rays") {
            uint64_t rays = 0;
            auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), rays);
            if (ec != std::errc() || end != value.data() + value.size()) {
                return InvalidArgumentError(
                    "pager tunable nearly_empty_rays={}: expected a ray count", value);
            }
            options->nearly_empty_rays = size_t(rays);
        } else if (key == "loaders") {
            int n = 0;
            auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
            if (ec != std::errc() || end != value.data() + value.size() || n < 1 || n > 64) {
                return InvalidArgumentError(
                    "pager tunable loaders={}: expected a thread count from 1 to 64", value);
            }
            options->loaders = n;
        } else if (key == "wave_overlap") {
            std::string v(value);
            char* end = nullptr;
            double f = std::strtod(v.c_str(), &end);
            if (v.empty() || end != v.c_str() + v.size() || !(f >= 0 && f <= 1)) {
                return InvalidArgumentError(
                    "pager tunable wave_overlap={}: expected a fraction in [0, 1]", value);
            }
            options->wave_overlap = f;
        } else if (key == "prefer_resident") {
            std::string v(value);
            char* end = nullptr;
            double f = std::strtod(v.c_str(), &end);
            if (v.empty() || end != v.c_str() + v.size() || !(f >= 0)) {
                return InvalidArgumentError(
                    "pager tunable prefer_resident={}: expected a fraction >= 0", value);
            }
            options->prefer_resident = f;
        } else {
            return InvalidArgumentError("unknown pager tunable '{}' (accepted: {})", key, kKeys);
        }
    }
    return Status::Ok();
}

bool KeepsCoarseLevels(const BrickBudgetMinimum& m, uint64_t brick_budget_bytes) {
    return m.kept_bytes > 0 && m.kept_bytes <= brick_budget_bytes / 2 &&
           m.kept_bytes + m.min_bytes <= brick_budget_bytes;
}

std::vector<bool> KeptLevels(const BrickSource& source, const BrickBudgetMinimum& m,
                             uint64_t brick_budget_bytes) {
    std::vector<bool> kept(source.slot_count(), false);
    // As many as half the budget holds while the largest bricks still fit, the smallest first, so
    // that the most bricks answer wide rays without a load: all of them where KeepsCoarseLevels.
    // Which ones changes what is loaded when, never the image.
    if (m.kept_bytes == 0 || m.min_bytes >= brick_budget_bytes) return kept;
    const uint64_t room = std::min(brick_budget_bytes / 2, brick_budget_bytes - m.min_bytes);
    std::vector<std::pair<uint64_t, uint32_t>> by_size;
    for (uint32_t b = 0; b < source.slot_count(); ++b) {
        if (KeptResident(source, b)) by_size.push_back({source.EstimatedResidentBytes(b), b});
    }
    std::sort(by_size.begin(), by_size.end());
    uint64_t used = 0;
    for (const auto& [bytes, slot] : by_size) {
        if (used + bytes > room) break;
        used += bytes;
        kept[slot] = true;
    }
    return kept;
}

bool KeptResident(const BrickSource& source, uint32_t slot) {
    const uint32_t level = source.LevelOfSlot(slot);
    return level > 0 && level + 1 == source.LevelsOf(source.BrickOfSlot(slot));
}

BrickBudgetMinimum MinimumBrickBudget(const BrickSource& source, bool prefetch) {
    BrickBudgetMinimum m;
    bool first = true, second = true;
    for (uint32_t b = 0; b < source.slot_count(); ++b) {
        uint64_t bytes = source.EstimatedResidentBytes(b);
        m.total_bytes += bytes;
        if (KeptResident(source, b)) {
            m.kept_bytes += bytes;
            continue;
        }
        if (bytes == 0) continue;  // a level its brick lacks
        if (first || bytes > m.largest_bytes) {
            if (!first) {
                m.second_brick = m.largest_brick;
                m.second_bytes = m.largest_bytes;
                second = false;
            }
            m.largest_brick = b;
            m.largest_bytes = bytes;
            first = false;
        } else if (second || bytes > m.second_bytes) {
            m.second_brick = b;
            m.second_bytes = bytes;
            second = false;
        }
    }
    if (second) {
        m.second_brick = m.largest_brick;
        m.second_bytes = 0;
    }
    // The kept levels stay resident only where they fit (KeepsCoarseLevels); without them the
    // largest bricks are what any budget must hold.
    m.min_bytes = m.largest_bytes + (prefetch ? m.second_bytes : 0);
    return m;
}

Pager::Pager(BrickSource& source, const PagerOptions& options, WaitingFn waiting)
    : source_(source),
      options_(options),
      waiting_(std::move(waiting)),
      resident_guard_(options.memory_bytes),
      state_(source.slot_count(), State::kAbsent),
      bytes_(source.slot_count(), 0),
      last_used_(source.slot_count(), 0),
      traffic_(source.slot_count(), 0),
      load_count_(source.slot_count(), 0),
      kept_(source.slot_count(), false),
      unused_prefetch_(source.slot_count(), false),
      prefetch_current_(store::kNoBrick) {
    estimate_.reserve(source.slot_count());
    for (uint32_t b = 0; b < source.slot_count(); ++b)
        estimate_.push_back(source.EstimatedResidentBytes(b));
    stats_.brick_budget_bytes = options.brick_budget_bytes;
}

std::string BrickBudgetMinimum::DescribeLargest(bool prefetch) const {
    return fmt::format("its largest brick, brick {}, takes {} ({} bytes) when resident{}",
                       largest_brick, FormatBytes(largest_bytes), largest_bytes,
                       prefetch && second_bytes > 0
                           ? fmt::format(", and prefetching needs room for the next-largest, "
                                         "brick {} ({})",
                                         second_brick, FormatBytes(second_bytes))
                           : std::string());
}

StatusOr<std::unique_ptr<Pager>> Pager::Create(BrickSource& source, const PagerOptions& options,
                                               WaitingFn waiting) {
    BrickBudgetMinimum need = MinimumBrickBudget(source, options.prefetch);
    if (source.slot_count() > 0 && options.brick_budget_bytes < need.min_bytes) {
        return ResourceExhaustedError(
            "brick memory budget {} ({} bytes) is too small for this model: {}; the minimum brick "
            "budget is {} ({} bytes)",
            FormatBytes(options.brick_budget_bytes), options.brick_budget_bytes,
            need.DescribeLargest(options.prefetch), FormatBytes(need.min_bytes), need.min_bytes);
    }
    std::unique_ptr<Pager> pager(new Pager(source, options, std::move(waiting)));
    pager->kept_ = KeptLevels(source, need, options.brick_budget_bytes);
    // Bricks an earlier render left resident: keep those that fit, drop the rest.
    for (uint32_t b = 0; b < source.slot_count(); ++b) {
        if (!source.IsResident(b)) continue;
        uint64_t bytes = 0;
        {
            StatusOr<BrickHandle> h = source.Acquire(b);
            if (!h.ok()) continue;
            bytes = (*h)->memory_bytes();
        }
        if (pager->committed_bytes_ + bytes <= options.brick_budget_bytes || !source.Evict(b)) {
            pager->state_[b] = State::kResident;
            pager->bytes_[b] = bytes;
            pager->committed_bytes_ += bytes;
        }
    }
    pager->stats_.peak_resident_bytes = pager->committed_bytes_;
    if (options.prefetch) {
        pager->loaders_.resize(size_t(std::max(1, options.loaders)));
        for (size_t i = 0; i < pager->loaders_.size(); ++i) {
            pager->loaders_[i].target = store::kNoBrick;
            pager->loaders_[i].thread = std::thread([p = pager.get(), i] { p->LoaderLoop(i); });
        }
    }
    return pager;
}

Pager::~Pager() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    loader_cv_.notify_all();
    for (Loader& l : loaders_) {
        if (l.thread.joinable()) l.thread.join();
    }
}

bool Pager::Claimed(uint32_t id) const {
    return std::any_of(loaders_.begin(), loaders_.end(),
                       [id](const Loader& l) { return l.target == id; });
}

uint32_t Pager::NextPrefetchTarget() const {
    uint32_t best = store::kNoBrick;
    for (uint32_t b = 0; b < prefetch_waiting_.size(); ++b) {
        if (b == prefetch_current_ || prefetch_waiting_[b] == 0 || state_[b] != State::kAbsent ||
            Claimed(b)) {
            continue;
        }
        if (best == store::kNoBrick || prefetch_waiting_[b] > prefetch_waiting_[best]) best = b;
    }
    return best;
}

uint32_t Pager::Pick(const std::vector<size_t>& waiting) {
    uint32_t fullest = 0;
    uint32_t resident = store::kNoBrick;
    std::lock_guard<std::mutex> lock(mutex_);
    for (uint32_t b = 0; b < waiting.size(); ++b) {
        if (waiting[b] > waiting[fullest]) fullest = b;
        if (waiting[b] > 0 && state_[b] == State::kResident &&
            (resident == store::kNoBrick || waiting[b] > waiting[resident])) {
            resident = b;
        }
    }
    if (state_[fullest] == State::kResident) return fullest;
    // Tracing a resident brick's rays now costs no load and may let the loader bring the fullest
    // brick in meanwhile; it pays when the resident brick's batch is large enough to be worth a
    // visit.
    if (resident != store::kNoBrick &&
        double(waiting[resident]) >= options_.prefer_resident * double(waiting[fullest])) {
        return resident;
    }
    return fullest;
}

void Pager::Reserve(uint32_t id, uint64_t bytes) {
    state_[id] = State::kLoading;
    bytes_[id] = bytes;
    committed_bytes_ += bytes;
    stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, committed_bytes_);
}

void Pager::Loaded(uint32_t id, uint64_t bytes, bool prefetched) {
    committed_bytes_ = committed_bytes_ - bytes_[id] + bytes;
    if (bytes > bytes_[id]) {
        ++stats_.estimate_misses;
        if (!warned_estimate_) {
            warned_estimate_ = true;
            log::Warning(
                "pager: brick {} takes {} bytes resident, more than the {} estimated before "
                "loading",
                id, bytes, bytes_[id]);
        }
        // Keep the budget on real numbers: make up for the difference at once.
        MakeRoom(0, id, std::nullopt);
    }
    state_[id] = State::kResident;
    bytes_[id] = bytes;
    last_used_[id] = ++tick_;
    unused_prefetch_[id] = prefetched;
    stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, committed_bytes_);
    ++stats_.loads;
    if (prefetched) ++stats_.prefetch_loads;
    if (++load_count_[id] > 1) ++stats_.reloads;
}

bool Pager::MakeRoom(uint64_t need, uint32_t exclude, std::optional<size_t> for_prefetch_of_rays) {
    const uint64_t budget = options_.brick_budget_bytes;
    if (committed_bytes_ + need <= budget) return true;
    struct Candidate {
        size_t waiting;
        uint64_t traffic;
        uint64_t last_used;
        uint32_t id;
    };
    std::vector<Candidate> candidates;
    const bool prefetch = for_prefetch_of_rays.has_value();
    for (uint32_t b = 0; b < state_.size(); ++b) {
        if (state_[b] != State::kResident || b == exclude || kept_[b]) continue;
        size_t w = waiting_ ? waiting_(b) : 0;
        if (prefetch && w >= options_.nearly_empty_rays) continue;
        // Nor does a prefetch evict what a prefetch loaded and nobody has traced yet for a brick
        // with no more rays waiting: the fresh brick's load has not paid for itself, and the new
        // one would pay less. Loaders evicting each other's fresh bricks (a thousand rays each)
        // took turns loading the same three bricks twenty times over while the scheduler drained
        // other bricks (docs/pager.md, "Policy").
        if (prefetch && unused_prefetch_[b] && w >= *for_prefetch_of_rays) continue;
        // Nearly empty queues count as empty when traffic decides: their few rays matter less than
        // how busy the brick is.
        const bool by_traffic = options_.evict == PagerOptions::Evict::kTraffic;
        if (by_traffic && w < options_.nearly_empty_rays) w = 0;
        candidates.push_back({w, by_traffic ? traffic_[b] : 0, last_used_[b], b});
    }
    // Emptiest queue first: the fewer rays wait for a brick, the fewer need it back soon (the paper
    // unloads a sub-model once almost all its rays are handled); least recently used breaks ties.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
        if (a.waiting != b.waiting) return a.waiting < b.waiting;
        if (a.traffic != b.traffic) return a.traffic < b.traffic;
        return a.last_used < b.last_used;
    });
    for (const Candidate& c : candidates) {
        if (committed_bytes_ + need <= budget) break;
        if (!source_.Evict(c.id)) continue;  // pinned: the batch being traced
        if (options_.trace != nullptr) {
            options_.trace->Instant(
                "evict", "pager",
                {{"brick", c.id}, {"waiting", c.waiting}, {"bytes", bytes_[c.id]}});
        }
        state_[c.id] = State::kAbsent;
        committed_bytes_ -= bytes_[c.id];
        bytes_[c.id] = 0;
        ++stats_.evictions;
    }
    return committed_bytes_ + need <= budget;
}

StatusOr<BrickHandle> Pager::Acquire(uint32_t id) {
    if (id >= state_.size()) return source_.Acquire(id);  // the source's error names the brick
    const auto start = std::chrono::steady_clock::now();
    std::unique_lock<std::mutex> lock(mutex_);
    last_used_[id] = ++tick_;
    unused_prefetch_[id] = false;
    ++stats_.acquires;
    if (state_[id] == State::kResident) ++stats_.resident_hits;
    bool waited = false;
    for (;;) {
        if (state_[id] == State::kResident) {
            // Pinned under the lock: evictions take it too, so the brick cannot go between check
            // and pin.
            if (waited) Stalled(id, start);
            return source_.Acquire(id);
        }
        if (state_[id] == State::kLoading) {
            waited = true;
            loaded_cv_.wait(lock);  // the loader is loading it
            continue;
        }
        for (Loader& l : loaders_) {
            if (l.target == id) {
                // A loader is still making room for it: take over (loads here may evict any
                // unpinned brick).
                l.cancel = true;
                loader_cv_.notify_all();
            }
        }
        const uint64_t need = estimate_[id];
        if (!MakeRoom(need, id, std::nullopt)) {
            const bool loader_loading =
                std::any_of(loaders_.begin(), loaders_.end(), [&](const Loader& l) {
                    return l.target != store::kNoBrick && l.target != id &&
                           state_[l.target] == State::kLoading;
                });
            if (loader_loading) {
                // Its brick becomes evictable once loaded. Meanwhile no loader may start another
                // load: the room it frees is the scheduler's (otherwise loaders that take turns
                // could starve it at small budgets).
                waited = true;
                scheduler_needs_room_ = true;
                loaded_cv_.wait(lock);
                scheduler_needs_room_ = false;
                loader_cv_.notify_all();
                continue;
            }
            return ResourceExhaustedError(
                "brick memory budget {}: cannot make room for brick {} ({}): {} of bricks are "
                "pinned",
                FormatBytes(options_.brick_budget_bytes), id, FormatBytes(need),
                FormatBytes(committed_bytes_));
        }
        Reserve(id, need);
        lock.unlock();
        resident_guard_.MakeRoom(need);
        StatusOr<BrickHandle> handle = source_.Acquire(id);
        lock.lock();
        if (!handle.ok()) {
            committed_bytes_ -= bytes_[id];
            bytes_[id] = 0;
            state_[id] = State::kAbsent;
            loaded_cv_.notify_all();
            Stalled(id, start);
            return handle.status();
        }
        Loaded(id, (*handle)->memory_bytes(), false);
        loaded_cv_.notify_all();
        Stalled(id, start);
        return handle;
    }
}

void Pager::Prefetch(const std::vector<size_t>& waiting, uint32_t current, size_t batch_rays) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (current < traffic_.size()) traffic_[current] += batch_rays;
        if (!options_.prefetch) return;
        prefetch_waiting_ = waiting;
        prefetch_current_ = current;
        ++request_epoch_;
    }
    loader_cv_.notify_all();
}

void Pager::BatchDone() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        ++batch_epoch_;
    }
    loader_cv_.notify_all();
    // Between loads too: the queues and spills of a render whose bricks all fit free and allocate
    // all the time, and the allocator's free pages would otherwise pile up past --memory with no
    // load to return them. A sixteenth of the limit is room for the next batch's new rays.
    resident_guard_.MakeRoom(options_.memory_bytes / 16);
}

bool Pager::Evict(uint32_t id) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (id >= state_.size() || state_[id] != State::kResident || !source_.Evict(id)) return false;
    state_[id] = State::kAbsent;
    committed_bytes_ -= bytes_[id];
    bytes_[id] = 0;
    ++stats_.evictions;
    return true;
}

void Pager::Stalled(uint32_t id, std::chrono::steady_clock::time_point start) {
    const auto end = std::chrono::steady_clock::now();
    stats_.stall_seconds += std::chrono::duration<double>(end - start).count();
    if (options_.trace != nullptr)
        options_.trace->Complete("stall", "pager", start, end, {{"brick", id}});
}

PagerStats Pager::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    PagerStats stats = stats_;
    stats.memory_returns = resident_guard_.returns();
    return stats;
}

void Pager::LoaderLoop(size_t index) {
    // Each load runs in a one-thread arena of its own: the render's workers are busy tracing, and
    // Embree builds the brick's BVH with the threads of the arena it is called from (outside any
    // arena it would use TBB's default pool: more threads than cores, each with its own build
    // buffers).
    tbb::task_arena arena(1);
    Loader& self = loaders_[index];
    if (options_.trace != nullptr) options_.trace->NameThread(fmt::format("loader {}", index + 1));
    uint64_t seen_epoch = 0;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        loader_cv_.wait(lock, [&] { return stop_ || request_epoch_ != seen_epoch; });
        if (stop_) return;
        seen_epoch = request_epoch_;
        const uint32_t target = NextPrefetchTarget();
        if (target == store::kNoBrick) continue;
        self.target = target;
        self.cancel = false;
        const uint64_t need = estimate_[target];
        bool reserved = false;
        for (;;) {
            if (stop_ || self.cancel) break;  // given up, or taken over by the scheduler
            if (!scheduler_needs_room_ && MakeRoom(need, target, prefetch_waiting_[target])) {
                Reserve(target, need);
                reserved = true;
                break;
            }
            // Nothing nearly empty to evict: wait for the batch to end (its brick is unpinned
            // then), or for a newer view of the queues (which may prefer another brick).
            const uint64_t batch = batch_epoch_;
            const uint64_t request = request_epoch_;
            const bool yielding = scheduler_needs_room_;
            loader_cv_.wait(lock, [&] {
                return stop_ || self.cancel || batch_epoch_ != batch || request_epoch_ != request ||
                       scheduler_needs_room_ != yielding;
            });
            if (request_epoch_ != request) {
                seen_epoch = request_epoch_ - 1;  // look again at once, with the newer view
                break;
            }
        }
        if (reserved) {
            lock.unlock();
            resident_guard_.MakeRoom(need);
            StatusOr<BrickHandle> handle = BrickHandle();
            arena.execute([&] { handle = source_.Acquire(target); });
            const bool ok = handle.ok();
            const uint64_t bytes = ok ? (*handle)->memory_bytes() : 0;
            // Unpinned at once: the brick stays resident until the scheduler picks it or a load
            // evicts it.
            if (ok) (*handle).Reset();
            lock.lock();
            if (ok) {
                Loaded(target, bytes, true);
            } else {
                // The source keeps the error (naming the brick) for the scheduler's own Acquire.
                committed_bytes_ -= bytes_[target];
                bytes_[target] = 0;
                state_[target] = State::kAbsent;
            }
            // Another brick may be worth loading from the same view: look again.
            seen_epoch = request_epoch_ - 1;
        }
        self.target = store::kNoBrick;
        self.cancel = false;
        loaded_cv_.notify_all();
    }
}

}  // namespace nave::render
