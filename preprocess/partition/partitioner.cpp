#include "preprocess/partition/partitioner.h"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <deque>

#include "preprocess/partition/bin_file.h"
#include "preprocess/partition/triangle_box.h"

namespace nave::preprocess {
namespace {

// Deterministic reservoir sampling (Vitter's algorithm R) with a SplitMix64 stream.
class Reservoir {
  public:
    Reservoir(size_t capacity, uint64_t seed) : capacity_(capacity), state_(seed) {}
    void Offer(const Vec3f& p) {
        ++seen_;
        if (points_.size() < capacity_) {
            points_.push_back(p);
            return;
        }
        uint64_t j = Next() % seen_;
        if (j < capacity_) points_[j] = p;
    }
    std::vector<Vec3f>& points() { return points_; }

  private:
    uint64_t Next() {
        uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    size_t capacity_;
    uint64_t state_;
    uint64_t seen_ = 0;
    std::vector<Vec3f> points_;
};

Vec3f Centroid(const Triangle& t) { return (t.p[0] + t.p[1] + t.p[2]) * (1.f / 3.f); }

Vec3f ClampTo(const Vec3f& p, const Bounds3f& b) { return Max(b.min, Min(b.max, p)); }

Bounds3d Grow(const Bounds3f& b, double margin) {
    return Bounds3d(Vec3d(b.min) - Vec3d(margin, margin, margin),
                    Vec3d(b.max) + Vec3d(margin, margin, margin));
}

// The kd-tree built from a bin's sample, before it joins the brick tree.
struct LocalNode {
    int axis = 3;
    float split = 0;
    int child[2] = {-1, -1};
    int leaf = -1;  // index into leaves (for axis == 3)
};
struct LocalLeaf {
    Bounds3f cell;
    std::vector<Vec3f> points;
    double estimate = 0;
    int node = 0;
    int depth = 0;  // below the bin's node
    bool splittable = true;
};

// Where a split pass sends triangles: the bin's local kd-tree and its leaves' cells grown by the
// margin (the grid step).
struct RouteTree {
    const std::vector<LocalNode>& nodes;
    const std::vector<LocalLeaf>& leaves;
    std::vector<Bounds3d> grown;
    float margin;
};

// The pass of a split: every triangle of `reader` to each leaf cell of `tree` it overlaps (its
// leaf's writer and sample), on `threads` threads, until `interrupt` holds a signal. A pipeline of
// chunks: read (LZ4) in order, routed on any thread, appended in order, so that each leaf receives
// its triangles in the bin's order and the bins (and the store) do not depend on the thread count.
Status RoutePass(BinReader& reader, const RouteTree& tree, int threads,
                 std::vector<std::unique_ptr<BinWriter>>& writers, std::vector<Reservoir>& samples,
                 ProgressBar& progress, const TempDir& temp, const std::atomic<int>* interrupt) {
    // A chunk of the bin and where its triangles go: (triangle, leaf) pairs in the chunk's order;
    // kUnsampled marks a triangle kept in a cell it touches only through rounding.
    struct Chunk {
        std::vector<Triangle> triangles;
        std::vector<std::pair<uint32_t, uint32_t>> routes;
    };
    constexpr uint32_t kUnsampled = 1u << 31;
    constexpr size_t kChunkTriangles = size_t(1) << 15;
    const size_t tokens = 2 * size_t(std::max(1, threads));
    std::vector<std::unique_ptr<Chunk>> pool;  // chunks recycled, at most `tokens` of them
    std::mutex pool_mutex;
    const float m = tree.margin;
    Status failure;  // set by the first and the last stage only, which run one at a time

    auto read = [&](tbb::flow_control& flow) -> Chunk* {
        std::unique_ptr<Chunk> chunk;
        {
            std::lock_guard<std::mutex> lock(pool_mutex);
            if (!pool.empty()) {
                chunk = std::move(pool.back());
                pool.pop_back();
            }
        }
        if (!chunk) chunk = std::make_unique<Chunk>();
        chunk->triangles.clear();
        Status cancelled = CheckCancelled(interrupt);
        StatusOr<bool> more =
            cancelled.ok() ? reader.Read(chunk->triangles, kChunkTriangles) : cancelled;
        if (!more.ok() || !*more || !failure.ok()) {
            if (!more.ok() && failure.ok()) failure = more.status();
            flow.stop();
            return nullptr;
        }
        return chunk.release();
    };
    auto route = [&](Chunk* chunk) -> Chunk* {
        chunk->routes.clear();
        std::vector<int> candidates, stack;
        for (size_t i = 0; i < chunk->triangles.size(); ++i) {
            const Triangle& t = chunk->triangles[i];
            Bounds3f box;
            for (const Vec3f& p : t.p) box.Extend(p);
            candidates.clear();
            stack.assign(1, 0);
            while (!stack.empty()) {
                const LocalNode& n = tree.nodes[size_t(stack.back())];
                stack.pop_back();
                if (n.axis == 3) {
                    candidates.push_back(n.leaf);
                    continue;
                }
                if (box.min[n.axis] - m <= n.split) stack.push_back(n.child[0]);
                if (box.max[n.axis] + m >= n.split) stack.push_back(n.child[1]);
            }
            bool placed = false;
            for (int c : candidates) {
                if (candidates.size() > 1 && !TriangleOverlapsBox(t.p, tree.grown[size_t(c)]))
                    continue;
                chunk->routes.emplace_back(uint32_t(i), uint32_t(c));
                placed = true;
            }
            // Only rounding can leave a triangle unplaced (it touches the parent cell): keep it
            // somewhere near.
            if (!placed && !candidates.empty())
                chunk->routes.emplace_back(uint32_t(i), uint32_t(candidates[0]) | kUnsampled);
        }
        return chunk;
    };
    auto append = [&](Chunk* chunk) {
        std::unique_ptr<Chunk> owned(chunk);
        for (const auto& [index, entry] : chunk->routes) {
            if (!failure.ok()) break;
            const uint32_t leaf = entry & ~kUnsampled;
            const Triangle& t = chunk->triangles[index];
            Status appended = writers[leaf]->Append(t);
            if (!appended.ok()) {
                failure = temp.Annotate(appended);
                break;
            }
            if (!(entry & kUnsampled))
                samples[leaf].Offer(ClampTo(Centroid(t), tree.leaves[leaf].cell));
        }
        progress.Add(chunk->triangles.size());
        std::lock_guard<std::mutex> lock(pool_mutex);
        pool.push_back(std::move(owned));
    };
    tbb::parallel_pipeline(
        tokens, tbb::make_filter<void, Chunk*>(tbb::filter_mode::serial_in_order, read) &
                    tbb::make_filter<Chunk*, Chunk*>(tbb::filter_mode::parallel, route) &
                    tbb::make_filter<Chunk*, void>(tbb::filter_mode::serial_in_order, append));
    return failure;
}

}  // namespace

int MaxSplitFanout(size_t split_buffer_bytes, uint64_t open_files) {
    const uint64_t by_files = open_files > 130 ? open_files - 128 : 2;
    const uint64_t by_memory = split_buffer_bytes / (2 * (size_t(16) << 10));
    return int(std::clamp<uint64_t>(std::min(by_files, by_memory), 2, 4096));
}

StatusOr<std::unique_ptr<BinWriter>> Partitioner::NewBin(size_t block_bytes) {
    auto created = BinWriter::Create(
        temp_.File("bin-" + std::to_string(bin_counter_.fetch_add(1)) + ".lz4"), block_bytes);
    if (!created.ok()) return temp_.Annotate(created.status());
    return created;
}

void Partitioner::AddTempBytes(int64_t delta) {
    int64_t now = temp_bytes_.fetch_add(delta) + delta;
    uint64_t peak = peak_temp_bytes_.load();
    while (now > 0 && uint64_t(now) > peak &&
           !peak_temp_bytes_.compare_exchange_weak(peak, uint64_t(now))) {
    }
}

Status Partitioner::Bin(TriangleSource& source, ProgressBar& progress) {
    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<BinWriter> writer, NewBin(config_.block_bytes));
    root_.file = writer->path();
    Reservoir sample(config_.root_sample, 1);
    std::vector<Triangle> batch;
    while (true) {
        NAVE_RETURN_IF_ERROR(CheckCancelled(config_.interrupt));
        NAVE_ASSIGN_OR_RETURN(bool more, source.Next(batch, 1 << 14));
        if (!more) break;
        for (const Triangle& t : batch) {
            for (const Vec3f& p : t.p) bounds_.Extend(Vec3d(p));
            sample.Offer(Centroid(t));
            NAVE_RETURN_IF_ERROR(temp_.Annotate(writer->Append(t)));
        }
        source_triangles_ += batch.size();
        uint64_t done = source.progress_done();
        if (done > progress.done()) progress.Add(done - progress.done());
    }
    NAVE_RETURN_IF_ERROR(temp_.Annotate(writer->Close()));
    AddTempBytes(int64_t(writer->file_bytes()));
    root_.triangles = source_triangles_;
    root_.sample = std::move(sample.points());
    if (source_triangles_ == 0) return InvalidArgumentError("{}: no triangles", source.name());
    return Status::Ok();
}

uint64_t Partitioner::duplicated_triangles() const {
    uint64_t refs = 0;
    for (const LeafBin& l : leaves_) refs += l.triangles;
    return refs > source_triangles_ ? refs - source_triangles_ : 0;
}

Status Partitioner::Split(const Bounds3f& root, double margin, ProgressBar& progress) {
    margin_ = margin;
    progress_ = &progress;
    nodes_.assign(1, store::BrickTreeNode{});
    root_.cell = root;
    root_.node = 0;

    // Bins are split one at a time, each pass on every thread (SplitTask): the root's pass cuts
    // most of the model into leaves at once, and the few children still too big follow.
    tbb::task_arena arena(std::max(1, config_.threads));
    std::deque<Task> queue;
    queue.push_back(std::move(root_));
    Status status;
    arena.execute([&] {
        while (!queue.empty() && status.ok()) {
            Task task = std::move(queue.front());
            queue.pop_front();
            std::vector<Task> children;
            status = SplitTask(std::move(task), children);
            for (Task& c : children) queue.push_back(std::move(c));
        }
    });
    // Bigger bricks first: the encoder's threads balance better.
    std::sort(leaves_.begin(), leaves_.end(), [](const LeafBin& a, const LeafBin& b) {
        return a.triangles != b.triangles ? a.triangles > b.triangles : a.node < b.node;
    });
    return status;
}

Status Partitioner::SplitTask(Task task, std::vector<Task>& children) {
    NAVE_RETURN_IF_ERROR(CheckCancelled(config_.interrupt));
    const uint64_t leaf_max = LeafMaxTriangles(config_.brick_triangles);
    if (task.triangles <= leaf_max || task.depth + 2 >= int(store::BrickTree::kMaxDepth)) {
        std::lock_guard<std::mutex> lock(mutex_);
        leaves_.push_back(
            {task.file, task.cell, task.triangles, task.node, task.triangles > leaf_max});
        return Status::Ok();
    }

    // The local kd-tree: split the leaf with the largest estimate at the sample's median along its
    // longest axis, until every estimate is under the target or the fan-out limit is reached.
    std::vector<LocalNode> lnodes(1);
    std::vector<LocalLeaf> lleaves(1);
    lleaves[0].cell = task.cell;
    lleaves[0].points = std::move(task.sample);
    lleaves[0].estimate = double(task.triangles);
    lnodes[0].leaf = 0;
    const double target = double(config_.brick_triangles);
    while (int(lleaves.size()) < config_.max_fanout) {
        int best = -1;
        for (size_t i = 0; i < lleaves.size(); ++i) {
            if (lleaves[i].splittable && lleaves[i].estimate > target &&
                (best < 0 || lleaves[i].estimate > lleaves[best].estimate)) {
                best = int(i);
            }
        }
        if (best < 0) break;
        LocalLeaf& leaf = lleaves[best];
        int axis = leaf.cell.MaxAxis();
        float lo = leaf.cell.min[axis], hi = leaf.cell.max[axis];
        if (double(hi) - double(lo) < 8 * margin_ ||
            task.depth + leaf.depth + 2 >= int(store::BrickTree::kMaxDepth)) {
            leaf.splittable = false;
            continue;
        }
        float split = 0.5f * (lo + hi);
        std::vector<Vec3f>& pts = leaf.points;
        if (pts.size() >= 8) {
            auto mid = pts.begin() + pts.size() / 2;
            std::nth_element(pts.begin(), mid, pts.end(),
                             [axis](const Vec3f& a, const Vec3f& b) { return a[axis] < b[axis]; });
            split = (*mid)[axis];
        }
        // Keep the plane strictly inside the cell, away from its faces by a few grid steps.
        float guard = float(2 * margin_);
        if (!(split > lo + guard && split < hi - guard)) split = 0.5f * (lo + hi);
        LocalLeaf below, above;
        below.cell = above.cell = leaf.cell;
        below.depth = above.depth = leaf.depth + 1;
        below.cell.max[axis] = split;
        above.cell.min[axis] = split;
        for (const Vec3f& p : pts) (p[axis] < split ? below.points : above.points).push_back(p);
        double total = double(pts.size());
        below.estimate =
            total > 0 ? leaf.estimate * below.points.size() / total : leaf.estimate / 2;
        above.estimate =
            total > 0 ? leaf.estimate * above.points.size() / total : leaf.estimate / 2;
        // Triangles crossing the plane go to both sides; never let an estimate vanish entirely.
        below.estimate = std::max(below.estimate, 1.0);
        above.estimate = std::max(above.estimate, 1.0);
        int node = leaf.node;
        below.node = int(lnodes.size());
        above.node = int(lnodes.size() + 1);
        lnodes[node].axis = axis;
        lnodes[node].split = split;
        lnodes[node].leaf = -1;
        lnodes[node].child[0] = below.node;
        lnodes[node].child[1] = above.node;
        LocalNode nb, na;
        nb.leaf = best;
        na.leaf = int(lleaves.size());
        lnodes.push_back(nb);
        lnodes.push_back(na);
        lleaves[best] = std::move(below);
        lleaves.push_back(std::move(above));
    }
    if (lleaves.size() == 1) {
        // Nothing to split along (a cell a few grid steps wide): keep it as one oversized brick.
        std::lock_guard<std::mutex> lock(mutex_);
        leaves_.push_back({task.file, task.cell, task.triangles, task.node, true});
        return Status::Ok();
    }

    // One pass over the bin: each triangle to every leaf cell it overlaps (RoutePass).
    const size_t fanout = lleaves.size();
    const size_t block = std::clamp<size_t>(config_.split_buffer_bytes / (2 * fanout), 16 << 10,
                                            config_.block_bytes);
    std::vector<std::unique_ptr<BinWriter>> writers(fanout);
    std::vector<Reservoir> samples;
    RouteTree tree{lnodes, lleaves, std::vector<Bounds3d>(fanout), float(margin_)};
    for (size_t i = 0; i < fanout; ++i) {
        NAVE_ASSIGN_OR_RETURN(writers[i], NewBin(block));
        samples.emplace_back(config_.child_sample, uint64_t(task.node) * 1000 + i + 7);
        tree.grown[i] = Grow(lleaves[i].cell, margin_);
    }
    NAVE_ASSIGN_OR_RETURN(auto reader, BinReader::Open(task.file));
    NAVE_RETURN_IF_ERROR(RoutePass(*reader, tree, config_.threads, writers, samples, *progress_,
                                   temp_, config_.interrupt));
    reader.reset();
    std::error_code ec;
    int64_t parent_bytes = int64_t(std::filesystem::file_size(task.file, ec));
    if (ec) parent_bytes = 0;
    std::filesystem::remove(task.file, ec);
    AddTempBytes(-parent_bytes);
    int64_t child_bytes = 0;

    std::lock_guard<std::mutex> lock(mutex_);
    // Graft the local tree onto the brick tree: the task's leaf becomes the local root.
    std::vector<uint32_t> global(lnodes.size());
    global[0] = task.node;
    for (size_t i = 1; i < lnodes.size(); ++i) {
        global[i] = uint32_t(nodes_.size());
        nodes_.push_back(store::BrickTreeNode{});
    }
    for (size_t i = 0; i < lnodes.size(); ++i) {
        store::BrickTreeNode& g = nodes_[global[i]];
        if (lnodes[i].axis == 3) {
            g = store::BrickTreeNode{};
            continue;
        }
        g.axis = uint8_t(lnodes[i].axis);
        g.split = lnodes[i].split;
        g.child[0] = global[lnodes[i].child[0]];
        g.child[1] = global[lnodes[i].child[1]];
        g.brick = store::kNoBrick;
    }
    for (size_t i = 0; i < fanout; ++i) {
        NAVE_RETURN_IF_ERROR(temp_.Annotate(writers[i]->Close()));
        child_bytes += int64_t(writers[i]->file_bytes());
        uint64_t count = writers[i]->triangles();
        if (count == 0) {
            std::filesystem::remove(writers[i]->path(), ec);  // empty space: no brick
            continue;
        }
        Task child;
        child.file = writers[i]->path();
        child.cell = lleaves[i].cell;
        child.triangles = count;
        child.node = global[lleaves[i].node];
        child.depth = task.depth + lleaves[i].depth;
        child.sample = std::move(samples[i].points());
        // No progress (most triangles span the whole cell): stop splitting this one.
        if (count > task.triangles * 98 / 100) {
            leaves_.push_back({child.file, child.cell, child.triangles, child.node, true});
            continue;
        }
        children.push_back(std::move(child));
    }
    AddTempBytes(child_bytes);
    return Status::Ok();
}

}  // namespace nave::preprocess
