#include "src/render/bricks/brick_source.h"

#include <embree3/rtcore.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "src/core/trace.h"
#include "src/render/bricks/brick_cache.h"

namespace nave::render {

BrickHandle& BrickHandle::operator=(BrickHandle&& o) noexcept {
    if (this != &o) {
        Reset();
        source_ = o.source_;
        brick_ = o.brick_;
        o.source_ = nullptr;
        o.brick_ = nullptr;
    }
    return *this;
}

void BrickHandle::Reset() {
    if (source_ != nullptr && brick_ != nullptr) source_->Release(brick_->id());
    source_ = nullptr;
    brick_ = nullptr;
}

BrickSource::BrickSource(std::shared_ptr<EmbreeDevice> device, store::BrickTree tree,
                         std::vector<Bounds3f> cells, std::vector<store::MaterialRecord> materials,
                         Bounds3f bounds)
    : device_(std::move(device)),
      tree_(std::move(tree)),
      cells_(std::move(cells)),
      materials_(std::move(materials)),
      bounds_(bounds),
      brick_count_(uint32_t(cells_.size())),
      level_errors_(cells_.size(), 0.f) {
    slots_.reserve(cells_.size());
    for (size_t i = 0; i < cells_.size(); ++i) slots_.push_back(std::make_unique<Slot>());
    occupancy_ = std::make_unique<BrickOccupancy[]>(cells_.size());
}

uint32_t BrickSource::LevelsOf(uint32_t brick) const {
    const float* errors = LevelErrors(brick);
    uint32_t n = 1;
    while (n < level_count_ && std::isfinite(errors[n])) ++n;
    return n;
}

Status BrickSource::UseLevels(uint32_t max_levels) {
    {
        std::lock_guard<std::mutex> lock(stats_mutex_);
        if (stats_.resident_bytes != 0) {
            return InvalidArgumentError(
                "levels of detail cannot change while {} of bricks are resident",
                stats_.resident_bytes);
        }
    }
    uint32_t levels = 1;
    for (uint32_t b = 0; b < brick_count_; ++b)
        levels = std::max(levels, std::min(std::max(max_levels, 1u), StoredLevels(b)));
    level_count_ = levels;
    level_errors_.assign(size_t(brick_count_) * levels, std::numeric_limits<float>::infinity());
    coarsest_error_ = 0;
    for (uint32_t b = 0; b < brick_count_; ++b) {
        const uint32_t n = std::min(levels, StoredLevels(b));
        for (uint32_t l = 0; l < n; ++l) {
            level_errors_[size_t(b) * levels + l] = l == 0 ? 0.f : StoredLevelError(b, l);
            coarsest_error_ = std::max(coarsest_error_, level_errors_[size_t(b) * levels + l]);
        }
    }
    slots_.clear();
    for (size_t i = 0; i < size_t(brick_count_) * levels; ++i)
        slots_.push_back(std::make_unique<Slot>());
    return Status::Ok();
}

BrickSource::~BrickSource() = default;

void BrickSource::SetOccupancy(std::vector<std::unique_ptr<const store::OccupancyGrid>> grids) {
    NAVE_CHECK_EQ(grids.size(), size_t(brick_count()));
    for (uint32_t b = 0; b < brick_count_; ++b) {
        occupancy_[b].owned = std::move(grids[b]);
        occupancy_[b].grid.store(occupancy_[b].owned.get(), std::memory_order_release);
    }
    occupancy_known_ = true;
}

StatusOr<BrickHandle> BrickSource::Acquire(uint32_t id) {
    if (id >= slots_.size()) {
        return InvalidArgumentError(
            "brick slot {} requested but the model has {} (bricks x levels of detail)", id,
            slots_.size());
    }
    acquires_.fetch_add(1, std::memory_order_relaxed);
    Slot& slot = *slots_[id];
    // Pin first, then check: an evictor takes the slot lock and refuses while pins > 0. The pin and
    // the check are sequentially consistent, as are the evictor's clearing of `ready` and its
    // second look at the pins (Evict): each side writes one variable and then reads the other, and
    // only a single total order of the four makes sure that one of them sees the other's write
    // (with release and acquire alone, the evictor's read of the pins may pass its store to
    // `ready`, as x86's store buffer allows, and both sides would go on).
    slot.pins.fetch_add(1, std::memory_order_seq_cst);
    if (const ResidentBrick* b = slot.ready.load(std::memory_order_seq_cst))
        return BrickHandle(this, b);
    std::lock_guard<std::mutex> lock(slot.mutex);
    if (const ResidentBrick* b = slot.ready.load(std::memory_order_acquire))
        return BrickHandle(this, b);
    if (!slot.error.ok()) {
        slot.pins.fetch_sub(1, std::memory_order_acq_rel);
        return slot.error;
    }
    auto start = std::chrono::steady_clock::now();
    TraceSpan load(trace_, "load", "pager");
    load.AddArg({"brick", id});
    uint64_t bytes = 0;
    const bool cached = brick_cache_ != nullptr && brick_cache_->Has(id);
    TraceSpan decode(trace_, cached ? "read from the brick cache" : "read and decode", "pager");
    // The mesh ends in pages of its own (ResidentMesh): read back from the cache straight into
    // them, or decoded into the heap and copied, so that what the heap holds is freed before the
    // next load.
    StatusOr<ResidentMesh> mesh = ResidentMesh();
    if (cached) {
        mesh = brick_cache_->Get(id);
    } else {
        if (decode_limit_ > 0) {
            std::unique_lock<std::mutex> decode_lock(decode_mutex_);
            decode_cv_.wait(decode_lock, [&] { return decodes_ < decode_limit_; });
            ++decodes_;
        }
        StatusOr<store::BrickMesh> decoded = LoadMesh(id, &bytes);
        if (decoded.ok() && brick_cache_ != nullptr) {
            TraceSpan put(trace_, "write to the brick cache", "pager");
            brick_cache_->Put(id, *decoded);
        }
        mesh = decoded.ok() ? ResidentMesh::CopyOf(*decoded)
                            : StatusOr<ResidentMesh>(decoded.status());
        if (decode_limit_ > 0) {
            {
                std::lock_guard<std::mutex> decode_lock(decode_mutex_);
                --decodes_;
            }
            decode_cv_.notify_one();
        }
    }
    decode.End();
    if (mesh.ok()) load.AddArg({"triangles", mesh->TriangleCount()});
    load.AddArg({"bytes_read", bytes});
    TraceSpan build(trace_, "bvh build", "pager");
    StatusOr<std::unique_ptr<ResidentBrick>> built =
        mesh.ok()
            ? ResidentBrick::Build(
                  *device_, id, cells_[BrickOfSlot(id)], std::move(mesh).value(), &alpha_masks_,
                  bvh_,
                  {LevelOfSlot(id), LevelErrors(BrickOfSlot(id))[LevelOfSlot(id)], coarsest_error_})
            : StatusOr<std::unique_ptr<ResidentBrick>>(mesh.status());
    build.End();
    if (built.ok() && medium_scale_) {
        TraceSpan medium(trace_, "read the medium", "pager");
        const uint32_t brick = BrickOfSlot(id);
        StatusOr<std::shared_ptr<const DensityField>> piece =
            LoadMediumPiece(brick, *medium_scale_, &bytes);
        if (piece.ok()) {
            // The directory's figure, so that the pager's accounting matches the estimate.
            (*built)->AttachMedium(std::move(piece).value(), MediumPieceBytes(brick));
        } else {
            built = piece.status();
        }
    }
    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!built.ok()) {
        slot.error = built.status().WithContext(
            LevelOfSlot(id) == 0
                ? fmt::format("loading brick {}", id)
                : fmt::format("loading brick {} at level {}", BrickOfSlot(id), LevelOfSlot(id)));
        slot.pins.fetch_sub(1, std::memory_order_acq_rel);
        return slot.error;
    }
    slot.brick = std::move(built).value();
    if (LevelOfSlot(id) == 0 && make_occupancy_.load(std::memory_order_relaxed)) {
        // Level 0's slot lock is held: one writer per brick.
        BrickOccupancy& o = occupancy_[BrickOfSlot(id)];
        if (o.owned == nullptr) {
            const ResidentMesh& m = slot.brick->mesh();
            o.owned = std::make_unique<const store::OccupancyGrid>(
                store::OccupancyGrid::Of(m.positions, m.indices));
            o.grid.store(o.owned.get(), std::memory_order_release);
        }
    }
    {
        std::lock_guard<std::mutex> stats_lock(stats_mutex_);
        stats_.loads += 1;
        stats_.bytes_read += bytes;
        stats_.load_seconds += seconds;
        stats_.resident_bytes += slot.brick->memory_bytes();
        stats_.peak_resident_bytes = std::max(stats_.peak_resident_bytes, stats_.resident_bytes);
    }
    slot.ready.store(slot.brick.get(), std::memory_order_release);
    return BrickHandle(this, slot.brick.get());
}

void BrickSource::SetAlphaMasks(AlphaMasks masks) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    NAVE_CHECK_EQ(stats_.resident_bytes, 0u) << "alpha masks set while bricks are resident";
    alpha_masks_ = std::move(masks);
}

Status BrickSource::UseStoredMedium(float scale) {
    NAVE_RETURN_IF_ERROR(HasStoredMedium());
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (stats_.resident_bytes != 0)
        return InvalidArgumentError(
            "the stored medium cannot be taken up while {} of bricks are "
            "resident",
            stats_.resident_bytes);
    medium_scale_ = scale;
    return Status::Ok();
}

Status BrickSource::SetBvhSettings(const BvhSettings& bvh) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (bvh == bvh_) return Status::Ok();
    if (stats_.resident_bytes != 0) {
        return InvalidArgumentError(
            "the BVH settings of a brick source cannot change while {} of bricks are resident",
            stats_.resident_bytes);
    }
    bvh_ = bvh;
    return Status::Ok();
}

void BrickSource::Release(uint32_t id) {
    uint32_t before = slots_[id]->pins.fetch_sub(1, std::memory_order_acq_rel);
    NAVE_CHECK_GT(before, 0u) << "brick " << id << " released more often than acquired";
}

bool BrickSource::IsResident(uint32_t id) const {
    return id < slots_.size() && slots_[id]->ready.load(std::memory_order_acquire) != nullptr;
}

bool BrickSource::Evict(uint32_t id) {
    if (id >= slots_.size()) return false;
    Slot& slot = *slots_[id];
    std::lock_guard<std::mutex> lock(slot.mutex);
    if (slot.brick == nullptr || slot.pins.load(std::memory_order_acquire) != 0) return false;
    slot.ready.store(nullptr, std::memory_order_seq_cst);
    // A reader that pinned between our check and the store above would hold a dangling pointer;
    // re-check (sequentially consistent with the store above: Acquire says why).
    if (slot.pins.load(std::memory_order_seq_cst) != 0) {
        slot.ready.store(slot.brick.get(), std::memory_order_release);
        return false;
    }
    uint64_t bytes = slot.brick->memory_bytes();
    slot.brick.reset();
    std::lock_guard<std::mutex> stats_lock(stats_mutex_);
    stats_.evictions += 1;
    stats_.resident_bytes -= bytes;
    return true;
}

BrickSourceStats BrickSource::stats() const {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    BrickSourceStats s = stats_;
    s.acquires = acquires_.load(std::memory_order_relaxed);
    return s;
}

}  // namespace nave::render
