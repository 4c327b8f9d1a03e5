#include "preprocess/preprocess.h"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "core/log.h"
#include "core/memory.h"
#include "core/progress.h"
#include "preprocess/abbey/abbey_source.h"
#include "preprocess/import/importer.h"
#include "preprocess/partition/bin_file.h"
#include "preprocess/partition/brick_builder.h"
#include "preprocess/partition/partitioner.h"
#include "preprocess/partition/temp_dir.h"
#include "preprocess/texture_convert.h"
#include "store/store_writer.h"

namespace nave::preprocess {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// Memory the run needs besides the bricks being encoded: the reading batch, the root bin's block
// buffers, the sample, the split buffers per thread, and a margin for the allocator and libraries.
constexpr uint64_t kFixedBytes = 48ull << 20;

std::string OptionsText(const PreprocessOptions& o, uint64_t brick_triangles, uint64_t budget,
                        double step, int threads, const std::string& units) {
    return fmt::format(
        "brick-triangles={} memory={} precision={} threads={} draco-speed={} "
        "derived-normal-error={} verify-every={} units={}",
        brick_triangles, budget, step, threads, o.encode.draco_speed,
        o.encode.derived_normal_error_deg, o.verify_every, units);
}

/// Removes the texture folder of a run that fails, unless it existed before the run (it may hold
/// textures an earlier store still uses).
class TextureFolderGuard {
  public:
    explicit TextureFolderGuard(std::filesystem::path folder) : folder_(std::move(folder)) {
        std::error_code ec;
        existed_ = std::filesystem::exists(folder_, ec);
    }
    ~TextureFolderGuard() {
        std::error_code ec;
        if (!committed_ && !existed_) std::filesystem::remove_all(folder_, ec);
    }
    void Commit() { committed_ = true; }

  private:
    std::filesystem::path folder_;
    bool existed_ = false, committed_ = false;
};

}  // namespace

double DefaultGridStep(double diagonal) { return diagonal > 0 ? diagonal / double(1 << 20) : 1e-6; }

StatusOr<PreprocessStats> RunPreprocess(const PreprocessOptions& options) {
    const auto start = Clock::now();
    InstallInterruptHandlers();
    PreprocessStats stats;
    if (options.output.empty()) return InvalidArgumentError("no output file given (-o MODEL.nave)");
    if (options.brick_triangles != 0 && options.brick_triangles < kMinBrickTriangles) {
        return InvalidArgumentError("--brick-triangles {}: expected at least {}",
                                    options.brick_triangles, kMinBrickTriangles);
    }
    stats.threads = options.threads > 0 ? options.threads
                                        : int(std::max(1u, std::thread::hardware_concurrency()));
    stats.memory_budget =
        options.memory_bytes > 0 ? options.memory_bytes : PhysicalMemoryBytes() / 4;

    // The budget must hold one brick's work (the largest a leaf may be: 5/4 of the target). Without
    // --brick-triangles, bricks get the default size, or the largest whose work fits the budget.
    const uint64_t fit = stats.memory_budget > kFixedBytes
                             ? (stats.memory_budget - kFixedBytes) / kEncodeBytesPerTriangle * 4 / 5
                             : 0;
    uint64_t brick_triangles = options.brick_triangles;
    if (brick_triangles == 0) {
        brick_triangles = std::clamp<uint64_t>(fit, kMinBrickTriangles, kDefaultBrickTriangles);
        if (brick_triangles < kDefaultBrickTriangles) {
            log::Info(
                "preprocess: bricks of {} triangles (the largest whose work fits --memory {})",
                brick_triangles, FormatBytes(stats.memory_budget));
        }
    }
    const uint64_t leaf_max = brick_triangles + brick_triangles / 4;
    const uint64_t per_brick = leaf_max * kEncodeBytesPerTriangle;
    if (stats.memory_budget < kFixedBytes + per_brick) {
        return ResourceExhaustedError(
            "--memory {} cannot hold the work for one brick: {} triangles x {} bytes = {} plus {} "
            "fixed; raise "
            "--memory to at least {} or lower --brick-triangles to at most {}",
            FormatBytes(stats.memory_budget), leaf_max, kEncodeBytesPerTriangle,
            FormatBytes(per_brick), FormatBytes(kFixedBytes), FormatBytes(kFixedBytes + per_brick),
            fit);
    }

    std::unique_ptr<TriangleSource> source;
    if (!options.generate.empty()) {
        // Each producer thread of the generator buffers about 10 MiB of triangles. One producer
        // (7-13 M triangles/s) outruns the whole preprocess (about 1 M/s) anyway; a second one only
        // shortens the read phase, so it is left out of small budgets.
        const int producers = stats.memory_budget >= (1ull << 30) ? stats.threads : 1;
        NAVE_ASSIGN_OR_RETURN(source, OpenGenerator(options.generate, producers));
    } else {
        NAVE_ASSIGN_OR_RETURN(source, OpenModels(options.inputs));
    }
    stats.source_name = source->name();
    stats.units = source->units();

    RemoveStaleOutputTemporaries(options.output);
    RemoveStaleTextureTemporaries(options.output);
    std::filesystem::path temp_parent = !options.temp_dir.empty() ? options.temp_dir
                                        : options.output.has_parent_path()
                                            ? options.output.parent_path()
                                            : std::filesystem::path(".");
    NAVE_ASSIGN_OR_RETURN(TempDir temp, TempDir::Create(temp_parent));

    // Phase 1: read and bin.
    PartitionConfig config;
    config.brick_triangles = brick_triangles;
    config.threads = stats.threads;
    // A sixteenth of the budget for the split's block buffers, and as many leaves per pass as they
    // and the open-file limit allow.
    config.split_buffer_bytes = stats.memory_budget / 16;
    config.block_bytes =
        std::clamp<uint64_t>(config.split_buffer_bytes / (64 * 2), 16 << 10, 256 << 10);
    config.max_fanout = MaxSplitFanout(config.split_buffer_bytes);
    Partitioner partitioner(config, temp);
    auto phase = Clock::now();
    {
        ProgressBar bar("read", source->progress_total(),
                        source->units() == "m" && !options.generate.empty() ? "parts" : "bytes");
        NAVE_RETURN_IF_ERROR(partitioner.Bin(*source, bar));
        bar.Finish();
    }
    stats.read_seconds = Since(phase);
    stats.source_triangles = partitioner.source_triangles();
    stats.source_memory = source->memory_bytes();
    for (const std::string& w : source->warnings().Summary()) {
        log::Warning("{}", w);
        stats.warnings.push_back(w);
    }
    auto materials = source->materials();
    if (options.convert_textures)
        NAVE_RETURN_IF_ERROR(temp.Annotate(source->WriteGeneratedTextures(temp.path())));
    source.reset();  // frees importer memory (OBJ/PLY vertex arrays) before the split

    // Textures the materials reference become tiled, MIP-mapped files beside the store, and the
    // material table points at them (texture_convert.h). Texture names are relative to their
    // model's directory.
    TextureFolderGuard texture_folder(TextureFolderFor(options.output));
    uint64_t texture_reserve = 0;  // taken from the budget of the work that follows
    const bool any_texture =
        std::any_of(materials.begin(), materials.end(),
                    [](const store::MaterialRecord& m) { return !m.textures.empty(); });
    if (any_texture && !options.convert_textures) {
        for (store::MaterialRecord& m : materials) m.textures.clear();
    } else if (any_texture) {
        // OpenImageIO stays loaded to the end of the run: the rest of the work gets the budget
        // minus its cost.
        const uint64_t need = kFixedBytes + per_brick + kTextureConversionBytes;
        if (stats.memory_budget < need) {
            return ResourceExhaustedError(
                "--memory {} cannot hold texture conversion ({} for OpenImageIO) beside the work "
                "for one brick "
                "({}): raise --memory to at least {}, or pass --no-textures to store flat colours "
                "only",
                FormatBytes(stats.memory_budget), FormatBytes(kTextureConversionBytes),
                FormatBytes(need - kTextureConversionBytes), FormatBytes(need));
        }
        texture_reserve = kTextureConversionBytes;
        std::vector<std::filesystem::path> source_dirs;
        for (const auto& input : options.inputs)
            source_dirs.push_back(input.has_parent_path() ? input.parent_path()
                                                          : std::filesystem::path("."));
        source_dirs.push_back(temp.path());  // a generator's textures (WriteGeneratedTextures)
        NAVE_ASSIGN_OR_RETURN(TextureConvertStats textures,
                              ConvertTextures(&materials, source_dirs, options.output));
        for (const std::string& w : textures.warnings) {
            log::Warning("{}", w);
            stats.warnings.push_back(w);
        }
        stats.textures_converted = textures.converted;
        stats.texture_bytes = textures.bytes_written;
        stats.texture_seconds = textures.seconds;
    }

    // The global grid.
    const Bounds3d& b = partitioner.bounds();
    double diagonal = Length(b.max - b.min);
    stats.grid_step = options.precision > 0 ? options.precision : DefaultGridStep(diagonal);
    stats.max_error = stats.grid_step * std::sqrt(3.0) / 2;
    double extent = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
    if (extent / stats.grid_step > double(1 << 29)) {
        return InvalidArgumentError(
            "--precision {}: the model is {} units across, {} grid steps; at most 2^29 "
            "fit: use --precision {} or more",
            stats.grid_step, extent, extent / stats.grid_step, extent / double(1 << 29));
    }
    store::GlobalGrid grid;
    grid.origin = b.min;
    grid.step = stats.grid_step;
    // The root cell: the bounds grown by a grid step, so snapped positions stay inside.
    Bounds3f root(Vec3f(b.min) - Vec3f(1, 1, 1) * float(stats.grid_step),
                  Vec3f(b.max) + Vec3f(1, 1, 1) * float(stats.grid_step));

    // Phase 2: split.
    phase = Clock::now();
    {
        ProgressBar bar("split", 0, "triangles");
        NAVE_RETURN_IF_ERROR(partitioner.Split(root, stats.grid_step, bar));
        bar.Finish();
    }
    stats.split_seconds = Since(phase);
    stats.duplicated_triangles = partitioner.duplicated_triangles();
    const std::vector<LeafBin>& leaves = partitioner.leaves();
    std::vector<store::BrickTreeNode>& nodes = partitioner.nodes();

    // Phase 3: encode on several threads, append as bricks finish. Each thread keeps its buffers
    // (sized by the largest brick it met), so the budget bounds the number of encoding threads.
    const uint64_t encode_budget = stats.memory_budget - kFixedBytes - texture_reserve;
    uint64_t largest = 0;
    for (const LeafBin& leaf : leaves) largest = std::max(largest, leaf.triangles);
    const int encode_threads = int(std::clamp<uint64_t>(
        encode_budget / std::max<uint64_t>(1, largest * kEncodeBytesPerTriangle), 1,
        uint64_t(stats.threads)));
    for (const LeafBin& leaf : leaves) {
        if (leaf.oversized) ++stats.oversized_bricks;
        uint64_t need = leaf.triangles * kEncodeBytesPerTriangle;
        if (need > encode_budget) {
            return ResourceExhaustedError(
                "a brick of {} triangles (cell {} could not be split further: its triangles "
                "overlap) needs {} to "
                "encode, more than --memory {} allows; raise --memory to at least {}",
                leaf.triangles, fmt::streamed(leaf.cell), FormatBytes(need),
                FormatBytes(stats.memory_budget),
                FormatBytes(need + kFixedBytes + texture_reserve));
        }
    }
    store::StoreProvenance provenance;
    for (const auto& in : options.inputs) provenance.source_files.push_back(in.string());
    if (!options.generate.empty()) provenance.source_files.push_back(options.generate);
    provenance.tool_version = options.tool_version;
    provenance.options = OptionsText(options, brick_triangles, stats.memory_budget, stats.grid_step,
                                     stats.threads, stats.units);
    NAVE_ASSIGN_OR_RETURN(auto writer,
                          store::StoreWriter::Create(options.output, grid, provenance));

    phase = Clock::now();
    uint64_t total_refs = 0;
    for (const LeafBin& leaf : leaves) total_refs += leaf.triangles;
    ProgressBar bar("encode", total_refs, "triangles");
    std::mutex mutex;
    size_t next = 0;
    Status failure;
    // Bricks are appended in leaf order whatever order the threads finish them in, so that brick
    // ids, and the store's bytes, do not depend on the thread count. A finished brick waits here
    // (compressed) until the leaves before it are appended.
    std::map<size_t, std::optional<store::EncodedBrick>> finished;
    size_t next_append = 0;
    auto append_ready = [&]() -> Status {  // with `mutex` held
        for (auto it = finished.begin(); it != finished.end() && it->first == next_append;
             it = finished.erase(it), ++next_append) {
            if (!it->second) continue;  // every triangle collapsed: no brick
            const store::EncodedBrick& encoded = *it->second;
            NAVE_ASSIGN_OR_RETURN(uint32_t id, writer->Append(encoded));
            nodes[leaves[it->first].node].brick = id;
            stats.stored_triangles += encoded.triangle_count;
            stats.collapsed_triangles += encoded.dropped_triangle_count;
            ++stats.bricks;
        }
        return Status::Ok();
    };
    auto worker = [&] {
        std::vector<Triangle> triangles;
        BrickBuilder builder;
        while (true) {
            const LeafBin* leaf = nullptr;
            size_t index = 0;
            {
                std::lock_guard<std::mutex> lock(mutex);
                if (next >= leaves.size() || !failure.ok()) return;
                index = next++;
                leaf = &leaves[index];
            }
            Status s = [&]() -> Status {
                NAVE_RETURN_IF_ERROR(CheckCancelled());
                triangles.clear();
                triangles.reserve(leaf->triangles);
                NAVE_ASSIGN_OR_RETURN(auto reader, BinReader::Open(leaf->file));
                while (true) {
                    NAVE_ASSIGN_OR_RETURN(bool more, reader->Read(triangles, 1 << 16));
                    if (!more) break;
                }
                reader.reset();
                std::error_code ec;
                std::filesystem::remove(leaf->file, ec);
                const BuiltBrick& built = builder.Build(triangles, grid);
                std::optional<store::EncodedBrick> encoded;
                store::EncodeOptions encode = options.encode;
                encode.verify = options.verify_every > 0 && index % options.verify_every == 0;
                if (!built.mesh.indices.empty()) {
                    NAVE_ASSIGN_OR_RETURN(encoded,
                                          store::EncodeBrick(built.mesh, leaf->cell, grid, encode));
                }
                std::lock_guard<std::mutex> lock(mutex);
                stats.collapsed_triangles += built.collapsed_triangles;
                stats.verified_bricks += encoded.has_value() && encode.verify;
                finished.emplace(index, std::move(encoded));
                return append_ready();
            }();
            bar.Add(leaf->triangles);
            if (!s.ok()) {
                std::lock_guard<std::mutex> lock(mutex);
                if (failure.ok()) failure = s;
                return;
            }
        }
    };
    {
        std::vector<std::thread> threads;
        for (int i = 1; i < encode_threads; ++i) threads.emplace_back(worker);
        worker();
        for (auto& t : threads) t.join();
    }
    NAVE_RETURN_IF_ERROR(failure);
    if (encode_threads < stats.threads) {
        log::Info(
            "encoded on {} threads of {}: the memory budget holds {} bricks of {} triangles at "
            "once",
            encode_threads, stats.threads, encode_threads, largest);
    }
    bar.Finish();
    stats.encode_seconds = Since(phase);
    for (const auto& n : nodes) {
        if (n.IsLeaf() && n.brick == store::kNoBrick) ++stats.empty_cells;
    }
    NAVE_RETURN_IF_ERROR(CheckCancelled());
    store::BrickTree tree(root, nodes);
    NAVE_RETURN_IF_ERROR(writer->Finish(materials, tree, stats.source_triangles));
    texture_folder.Commit();
    stats.output_bytes = writer->bytes_written();
    stats.peak_temp_bytes = partitioner.peak_temp_bytes();
    stats.seconds = Since(start);
    stats.peak_rss = PeakRssBytes();
    return stats;
}

std::string FormatSummary(const PreprocessStats& s) {
    double dup = s.source_triangles
                     ? 100.0 * double(s.duplicated_triangles) / double(s.source_triangles)
                     : 0;
    std::string out = fmt::format(
        "input:       {} ({} triangles, units: {})\n"
        "bricks:      {} (+{} empty cells), {} stored triangles, {} duplicated across cells "
        "({:.2f} %); {} decoded again to check them\n"
        "grid:        step {:.6g}, max error {:.6g} (model units)\n"
        "on disk:     {} ({:.2f} bytes per input triangle); temporary files peaked at {}\n"
        "time:        {} (read {}, split {}, encode {}), {} triangles/s on {} threads\n"
        "memory:      peak {} of a {} budget (importer held {})",
        s.source_name, FormatCount(double(s.source_triangles)), s.units, s.bricks, s.empty_cells,
        FormatCount(double(s.stored_triangles)), FormatCount(double(s.duplicated_triangles)), dup,
        s.verified_bricks, s.grid_step, s.max_error, FormatBytes(s.output_bytes),
        s.source_triangles ? double(s.output_bytes) / double(s.source_triangles) : 0.0,
        FormatBytes(s.peak_temp_bytes), FormatDuration(s.seconds), FormatDuration(s.read_seconds),
        FormatDuration(s.split_seconds), FormatDuration(s.encode_seconds),
        FormatCount(double(s.source_triangles) / std::max(s.seconds, 1e-9)), s.threads,
        FormatBytes(s.peak_rss), FormatBytes(s.memory_budget), FormatBytes(s.source_memory));
    if (s.collapsed_triangles > 0) {
        out += fmt::format("\nnote:        {} triangles smaller than the grid step were dropped",
                           s.collapsed_triangles);
    }
    if (s.oversized_bricks > 0) {
        out += fmt::format(
            "\nnote:        {} bricks exceed the target (triangles too large or overlapping to "
            "split)",
            s.oversized_bricks);
    }
    if (s.textures_converted > 0) {
        out += fmt::format("\ntextures:    {} converted to tiled MIP-maps, {} in {}",
                           s.textures_converted, FormatBytes(s.texture_bytes),
                           FormatDuration(s.texture_seconds));
    }
    for (const auto& w : s.warnings) out += "\nwarning:     " + w;
    return out;
}

}  // namespace nave::preprocess
