#pragma once
// Out-of-core kd partition of a triangle stream into bricks.
//
// Phase 1 (Bin): the source is streamed once into an LZ4-compressed temporary bin, while its
// bounds, its triangle count and a reservoir sample of triangle centroids are gathered. Phase 2
// (Split): a bin with more triangles than a brick may hold is split: the sample gives a kd-tree
// (median of the sample along the cell's longest axis, repeated until each leaf's estimated count
// is under the target, at most max_fanout leaves), then one pass over the bin, on every thread,
// sends each triangle to every leaf cell it overlaps (exact triangle/box test, cells grown by the
// grid step so that snapping cannot move a triangle out of a cell that needs it). Children still
// too big are split again. Empty cells get no brick. The result is the tree's nodes and the leaf
// bins, ready to be encoded.
//
// Memory: the sample (12 bytes per point), one block buffer per open bin (two copies of a block),
// two chunks of 32 K triangles per thread in the pass's pipeline; never the whole bin.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include "preprocess/partition/bin_file.h"
#include "preprocess/partition/temp_dir.h"
#include "preprocess/triangle_source.h"
#include "src/core/progress.h"
#include "src/core/status.h"
#include "store/brick_tree.h"

namespace nave::preprocess {

struct PartitionConfig {
    /// Target triangles per brick; a leaf may hold up to LeafMaxTriangles(brick_triangles).
    uint64_t brick_triangles = 1'000'000;
    size_t block_bytes =
        256 << 10;    ///< the root bin's block size (uncompressed), and the most for others
    int threads = 1;  ///< threads of each bin's split pass
    size_t root_sample = 1 << 18;   ///< centroids sampled from the whole input
    size_t child_sample = 1 << 12;  ///< per child bin
    /// Leaves one split pass may cut a bin into: every one is an open file with its block buffers.
    /// The root's pass cuts a model of up to max_fanout bricks at once (MaxSplitFanout).
    int max_fanout = 64;
    /// Memory for the block buffers of one pass's child bins (two copies of a block each; a block
    /// is 16 KiB to block_bytes).
    size_t split_buffer_bytes = size_t(64) << 20;
    /// Set by the caller (its signal handler) to a signal number to stop the work: Cancelled.
    const std::atomic<int>* interrupt = nullptr;
};

/// The most triangles a leaf of a `brick_triangles` target may hold before it is split again: 5/4
/// of the target (rounded down). Also the largest brick the encoder's memory must be planned for.
constexpr uint64_t LeafMaxTriangles(uint64_t brick_triangles) {
    return brick_triangles + brick_triangles / 4;
}

/// The most leaves one split pass may cut a bin into (PartitionConfig::max_fanout): each is an open
/// file with two block buffers of 16 KiB or more, within `split_buffer_bytes` and `open_files`
/// (the process's open-file limit, less 128 files for the rest), from 2 to 4096.
int MaxSplitFanout(size_t split_buffer_bytes, uint64_t open_files);

/// A bin of triangles and the tree leaf it belongs to.
struct LeafBin {
    std::filesystem::path file;
    Bounds3f cell;
    uint64_t triangles = 0;
    uint32_t node = 0;  ///< index of its leaf in nodes()
    bool oversized =
        false;  ///< could not be split below the target (overlapping or huge triangles)
};

class Partitioner {
  public:
    Partitioner(PartitionConfig config, const TempDir& temp) : config_(config), temp_(temp) {}

    /// Phase 1. Streams `source` into the root bin. `progress` counts source progress units.
    Status Bin(TriangleSource& source, ProgressBar& progress);
    /// Bounds of the input's positions and its triangle count (after Bin).
    const Bounds3d& bounds() const { return bounds_; }
    uint64_t source_triangles() const { return source_triangles_; }

    /// Phase 2. `margin` is how much cells grow for the overlap test (the grid step); `root` the
    /// tree's box. `progress` counts triangles distributed.
    Status Split(const Bounds3f& root, double margin, ProgressBar& progress);

    const std::vector<LeafBin>& leaves() const { return leaves_; }
    std::vector<store::BrickTreeNode>& nodes() { return nodes_; }
    /// Triangle references in leaf bins minus source triangles (triangles counted once per cell
    /// they cross).
    uint64_t duplicated_triangles() const;
    /// Largest bin bytes on disk at any one time (approximately), for the summary.
    uint64_t peak_temp_bytes() const { return peak_temp_bytes_.load(); }

  private:
    struct Task {
        std::filesystem::path file;
        Bounds3f cell;
        uint64_t triangles = 0;
        uint32_t node = 0;
        int depth = 0;
        std::vector<Vec3f> sample;
    };
    Status SplitTask(Task task, std::vector<Task>& children);
    void AddTempBytes(int64_t delta);
    /// A new bin in the temporary directory; a failure says where temporaries go
    /// (TempDir::Annotate).
    StatusOr<std::unique_ptr<BinWriter>> NewBin(size_t block_bytes);

    PartitionConfig config_;
    const TempDir& temp_;
    Bounds3d bounds_;
    uint64_t source_triangles_ = 0;
    Task root_;
    double margin_ = 0;
    std::mutex mutex_;
    std::vector<store::BrickTreeNode> nodes_;
    std::vector<LeafBin> leaves_;
    std::atomic<uint64_t> bin_counter_{0};
    std::atomic<int64_t> temp_bytes_{0};
    std::atomic<uint64_t> peak_temp_bytes_{0};
    ProgressBar* progress_ = nullptr;
};

}  // namespace nave::preprocess
