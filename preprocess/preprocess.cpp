#include "preprocess/preprocess.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>

#include "preprocess/abbey/abbey_source.h"
#include "preprocess/import/importer.h"
#include "preprocess/medium_cut.h"
#include "preprocess/partition/bin_file.h"
#include "preprocess/partition/brick_builder.h"
#include "preprocess/partition/partitioner.h"
#include "preprocess/partition/temp_dir.h"
#include "preprocess/preprocess_plan.h"
#include "preprocess/texture_convert.h"
#include "src/core/log.h"
#include "src/core/memory.h"
#include "src/core/progress.h"
#include "store/brick_levels.h"
#include "store/store_writer.h"

namespace nave::preprocess {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string OptionsText(const PreprocessOptions& o, const PreprocessPlan& plan, double step,
                        const std::string& units, const std::string& content) {
    const std::vector<double>& ratios = o.encode.levels.relative_errors;
    return fmt::format(
        "brick-triangles={} memory={} precision={} threads={} draco-speed={} "
        "derived-normal-error={} verify-every={} level-errors={} units={}{}{}",
        plan.brick_triangles, plan.memory_budget, step, plan.threads, o.encode.draco_speed,
        o.encode.derived_normal_error_deg, o.verify_every,
        ratios.empty() ? std::string("none") : fmt::format("{}", fmt::join(ratios, ",")), units,
        plan.medium.empty() ? std::string() : " medium-grid=" + o.medium_grid,
        content.empty() ? std::string() : " content=" + content);
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

/// The model files, or the generator with as many producers as the plan allows.
StatusOr<std::unique_ptr<TriangleSource>> OpenSource(const PreprocessOptions& options,
                                                     const PreprocessPlan& plan) {
    if (!options.generate.empty()) return OpenGenerator(options.generate, plan.generator_producers);
    return OpenModels(plan.models, options.precision);
}

/// Phase 1: streams the source into the partitioner's root bin, then takes its materials (and a
/// generator's textures, written into the temporary directory) and closes it, freeing what the
/// importer held before the split.
Status ReadIntoRootBin(std::unique_ptr<TriangleSource> source, const PreprocessOptions& options,
                       const TempDir& temp, Partitioner& partitioner,
                       std::vector<store::MaterialRecord>* materials, PreprocessStats* stats) {
    stats->source_name = source->name();
    stats->units = source->units();
    stats->content = source->content();
    const auto start = Clock::now();
    {
        ProgressBar bar("read", source->progress_total(), source->progress_unit());
        NAVE_RETURN_IF_ERROR(partitioner.Bin(*source, bar));
        bar.Finish();
    }
    stats->read_seconds = Since(start);
    stats->source_triangles = partitioner.source_triangles();
    stats->source_memory = source->memory_bytes();
    for (const std::string& w : source->warnings().Summary()) {
        log::Warning("{}", w);
        stats->warnings.push_back(w);
    }
    *materials = source->materials();
    if (options.convert_textures)
        NAVE_RETURN_IF_ERROR(temp.Annotate(source->WriteGeneratedTextures(temp.path())));
    return Status::Ok();
}

/// Textures the materials reference become tiled, MIP-mapped files beside the store, and the
/// material table points at them (texture_convert.h); without texture conversion their slots are
/// dropped. Texture names are relative to their model's directory, a generator's to the temporary
/// directory. Returns the memory set aside for the conversion (OpenImageIO stays loaded to the end
/// of the run), taken from the budget of the work that follows.
StatusOr<uint64_t> ConvertMaterialTextures(const PreprocessOptions& options,
                                           const PreprocessPlan& plan, const TempDir& temp,
                                           std::vector<store::MaterialRecord>* materials,
                                           PreprocessStats* stats) {
    const bool any_texture =
        std::any_of(materials->begin(), materials->end(),
                    [](const store::MaterialRecord& m) { return !m.textures.empty(); });
    if (!any_texture) return uint64_t(0);
    if (!options.convert_textures) {
        for (store::MaterialRecord& m : *materials) m.textures.clear();
        return uint64_t(0);
    }
    NAVE_ASSIGN_OR_RETURN(const uint64_t reserve, PlanTextureReserve(plan));
    std::vector<std::filesystem::path> source_dirs;
    for (const auto& input : plan.models)
        source_dirs.push_back(input.has_parent_path() ? input.parent_path()
                                                      : std::filesystem::path("."));
    source_dirs.push_back(temp.path());  // a generator's textures (WriteGeneratedTextures)
    NAVE_ASSIGN_OR_RETURN(TextureConvertStats textures,
                          ConvertTextures(materials, source_dirs, options.output));
    for (const std::string& w : textures.warnings) {
        log::Warning("{}", w);
        stats->warnings.push_back(w);
    }
    stats->textures_converted = textures.converted;
    stats->texture_bytes = textures.bytes_written;
    stats->texture_seconds = textures.seconds;
    return reserve;
}

/// Phase 2: cuts the root bin into leaf bins of at most LeafMaxTriangles (5/4 of the brick size).
Status SplitIntoLeaves(const GridPlan& grid, Partitioner& partitioner, PreprocessStats* stats) {
    const auto start = Clock::now();
    {
        ProgressBar bar("split", 0, "triangles");
        NAVE_RETURN_IF_ERROR(partitioner.Split(grid.root, grid.grid.step, bar));
        bar.Finish();
    }
    stats->split_seconds = Since(start);
    stats->duplicated_triangles = partitioner.duplicated_triangles();
    for (const LeafBin& leaf : partitioner.leaves()) stats->oversized_bricks += leaf.oversized;
    return Status::Ok();
}

/// What one encoding thread keeps from brick to brick: buffers sized by the largest brick it met.
struct EncodeBuffers {
    std::vector<Triangle> triangles;
    BrickBuilder builder;
};

/// One leaf's way through the encode pipeline.
struct EncodedLeaf {
    size_t index = 0;
    Status status;
    std::optional<store::EncodedBrick> brick;  ///< none when every triangle collapsed
    uint64_t collapsed_triangles = 0;
    bool verified = false;
};

/// Reads a leaf's bin (and deletes it), builds its mesh and encodes it.
EncodedLeaf EncodeLeaf(const LeafBin& leaf, size_t index, const store::GlobalGrid& grid,
                       const PreprocessOptions& options, EncodeBuffers& buffers) {
    EncodedLeaf out;
    out.index = index;
    out.status = [&]() -> Status {
        buffers.triangles.clear();
        buffers.triangles.reserve(leaf.triangles);
        NAVE_ASSIGN_OR_RETURN(auto reader, BinReader::Open(leaf.file));
        while (true) {
            NAVE_ASSIGN_OR_RETURN(bool more, reader->Read(buffers.triangles, 1 << 16));
            if (!more) break;
        }
        reader.reset();
        std::error_code ec;
        std::filesystem::remove(leaf.file, ec);
        const BuiltBrick& built = buffers.builder.Build(buffers.triangles, grid);
        out.collapsed_triangles = built.collapsed_triangles;
        if (built.mesh.indices.empty()) return Status::Ok();
        store::EncodeOptions encode = options.encode;
        encode.verify = options.verify_every > 0 && index % options.verify_every == 0;
        NAVE_ASSIGN_OR_RETURN(out.brick, store::EncodeBrick(built.mesh, leaf.cell, grid, encode));
        out.verified = encode.verify;
        return Status::Ok();
    }();
    return out;
}

/// Phase 3: encodes the leaves on `plan.threads` threads (`planned_threads` were asked for) and
/// appends them to `writer` in leaf order, whatever order the threads finish them in, so that brick
/// ids, and the store's bytes, do not depend on the thread count. A pipeline: leaves handed out in
/// order, encoded on any thread, appended in order; a brick finished early waits (compressed) for
/// the leaves before it.
Status EncodeBricks(const std::vector<LeafBin>& leaves, const EncodePlan& plan, int planned_threads,
                    const store::GlobalGrid& grid, const PreprocessOptions& options,
                    std::vector<store::BrickTreeNode>& nodes, store::StoreWriter& writer,
                    PreprocessStats* stats) {
    const auto start = Clock::now();
    uint64_t total_refs = 0;
    for (const LeafBin& leaf : leaves) total_refs += leaf.triangles;
    ProgressBar bar("encode", total_refs, "triangles");

    // At most plan.threads encode at once (the arena's concurrency), so at most that many buffers
    // exist; the tokens let finished bricks wait for a slow one before them without idling the
    // other threads.
    std::vector<std::unique_ptr<EncodeBuffers>> idle_buffers;
    std::mutex idle_mutex;
    std::atomic<bool> failed{false};
    Status failure;  // set by the last stage only, which runs one item at a time
    size_t next = 0;
    auto hand_out = [&](tbb::flow_control& flow) -> size_t {
        if (next >= leaves.size() || failed.load()) {
            flow.stop();
            return 0;
        }
        return next++;
    };
    auto encode = [&](size_t index) -> EncodedLeaf* {
        std::unique_ptr<EncodeBuffers> buffers;
        {
            std::lock_guard<std::mutex> lock(idle_mutex);
            if (!idle_buffers.empty()) {
                buffers = std::move(idle_buffers.back());
                idle_buffers.pop_back();
            }
        }
        if (!buffers) buffers = std::make_unique<EncodeBuffers>();
        auto leaf = std::make_unique<EncodedLeaf>();
        leaf->index = index;
        leaf->status = CheckCancelled(options.interrupt);
        if (leaf->status.ok() && !failed.load())
            *leaf = EncodeLeaf(leaves[index], index, grid, options, *buffers);
        {
            std::lock_guard<std::mutex> lock(idle_mutex);
            idle_buffers.push_back(std::move(buffers));
        }
        bar.Add(leaves[index].triangles);
        return leaf.release();
    };
    auto append = [&](EncodedLeaf* raw) {
        std::unique_ptr<EncodedLeaf> leaf(raw);
        if (!failure.ok()) return;
        failure = [&]() -> Status {
            NAVE_RETURN_IF_ERROR(leaf->status);
            stats->collapsed_triangles += leaf->collapsed_triangles;
            if (!leaf->brick) return Status::Ok();  // every triangle collapsed: no brick
            stats->verified_bricks += leaf->verified;
            NAVE_ASSIGN_OR_RETURN(uint32_t id, writer.Append(*leaf->brick));
            nodes[leaves[leaf->index].node].brick = id;
            stats->stored_triangles += leaf->brick->triangle_count;
            stats->collapsed_triangles += leaf->brick->dropped_triangle_count;
            stats->simplify_seconds += leaf->brick->simplify_seconds;
            const auto& levels = leaf->brick->levels;
            if (stats->level_triangles.size() < levels.size()) {
                stats->level_triangles.resize(levels.size(), 0);
                stats->level_bytes.resize(levels.size(), 0);
            }
            for (size_t k = 0; k < levels.size(); ++k) {
                stats->level_triangles[k] += levels[k].triangle_count;
                stats->level_bytes[k] += levels[k].mesh_bytes.size();
            }
            ++stats->bricks;
            return Status::Ok();
        }();
        if (!failure.ok()) failed = true;
    };
    tbb::task_arena arena(plan.threads);
    arena.execute([&] {
        tbb::parallel_pipeline(
            4 * size_t(plan.threads),
            tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order, hand_out) &
                tbb::make_filter<size_t, EncodedLeaf*>(tbb::filter_mode::parallel, encode) &
                tbb::make_filter<EncodedLeaf*, void>(tbb::filter_mode::serial_in_order, append));
    });
    NAVE_RETURN_IF_ERROR(failure);
    if (plan.threads < planned_threads) {
        log::Info(
            "encoded on {} threads of {}: the memory budget holds {} bricks of {} triangles at "
            "once",
            plan.threads, planned_threads, plan.threads, plan.largest_leaf);
    }
    bar.Finish();
    stats->encode_seconds = Since(start);
    return Status::Ok();
}

}  // namespace

double DefaultGridStep(double diagonal) { return diagonal > 0 ? diagonal / double(1 << 20) : 1e-6; }

StatusOr<PreprocessStats> RunPreprocess(const PreprocessOptions& options) {
    const auto start = Clock::now();
    if (!options.encode.levels.relative_errors.empty())
        NAVE_RETURN_IF_ERROR(store::ValidateLevelOptions(options.encode.levels));
    NAVE_ASSIGN_OR_RETURN(const PreprocessPlan plan,
                          PlanPreprocess(options, QueryMachineResources()));
    if (plan.brick_triangles_fitted) {
        log::Info("preprocess: bricks of {} triangles (the largest whose work fits --memory {})",
                  plan.brick_triangles, FormatBytes(plan.memory_budget));
    }
    PreprocessStats stats;
    stats.threads = plan.threads;
    stats.memory_budget = plan.memory_budget;
    // A bad medium fails the run before any model is read.
    if (!plan.medium.empty())
        NAVE_RETURN_IF_ERROR(CheckMediumGrid(plan.medium, options.medium_grid, plan.memory_budget));

    NAVE_ASSIGN_OR_RETURN(std::unique_ptr<TriangleSource> source, OpenSource(options, plan));
    RemoveStaleOutputTemporaries(options.output);
    RemoveStaleTextureTemporaries(options.output);
    NAVE_ASSIGN_OR_RETURN(TempDir temp, TempDir::Create(plan.temp_parent));
    PartitionConfig partition = plan.partition;
    partition.interrupt = options.interrupt;
    Partitioner partitioner(partition, temp);
    std::vector<store::MaterialRecord> materials;
    NAVE_RETURN_IF_ERROR(
        ReadIntoRootBin(std::move(source), options, temp, partitioner, &materials, &stats));

    TextureFolderGuard texture_folder(TextureFolderFor(options.output));
    NAVE_ASSIGN_OR_RETURN(const uint64_t texture_reserve,
                          ConvertMaterialTextures(options, plan, temp, &materials, &stats));

    NAVE_ASSIGN_OR_RETURN(const GridPlan grid, PlanGrid(options.precision, partitioner.bounds()));
    stats.grid_step = grid.grid.step;
    stats.max_error = grid.max_error;
    NAVE_RETURN_IF_ERROR(SplitIntoLeaves(grid, partitioner, &stats));

    const std::vector<LeafBin>& leaves = partitioner.leaves();
    NAVE_ASSIGN_OR_RETURN(const EncodePlan encode, PlanEncode(plan, texture_reserve, leaves));
    store::StoreProvenance provenance;
    for (const auto& in : options.inputs) provenance.source_files.push_back(in.string());
    if (!options.generate.empty()) provenance.source_files.push_back(options.generate);
    provenance.tool_version = options.tool_version;
    provenance.options = OptionsText(options, plan, stats.grid_step, stats.units, stats.content);
    NAVE_ASSIGN_OR_RETURN(auto writer,
                          store::StoreWriter::Create(options.output, grid.grid, provenance));
    std::vector<store::BrickTreeNode>& nodes = partitioner.nodes();
    NAVE_RETURN_IF_ERROR(
        EncodeBricks(leaves, encode, plan.threads, grid.grid, options, nodes, *writer, &stats));
    if (!plan.medium.empty()) {
        NAVE_RETURN_IF_ERROR(CheckCancelled(options.interrupt));
        NAVE_RETURN_IF_ERROR(StoreMedium(plan.medium, options.medium_grid, grid.root,
                                         plan.memory_budget, nodes, *writer, &stats));
        stats.bricks += stats.medium_only_bricks;
    }
    for (const auto& n : nodes) {
        if (n.IsLeaf() && n.brick == store::kNoBrick) ++stats.empty_cells;
    }

    NAVE_RETURN_IF_ERROR(CheckCancelled(options.interrupt));
    NAVE_RETURN_IF_ERROR(
        writer->Finish(materials, store::BrickTree(grid.root, nodes), stats.source_triangles));
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
    if (!s.level_triangles.empty()) {
        uint64_t level_bytes = 0;
        std::string each;
        for (size_t k = 0; k < s.level_triangles.size(); ++k) {
            level_bytes += s.level_bytes[k];
            each += fmt::format("{}level {}: {} triangles ({:.2f} % of the bricks'), {}",
                                k ? "; " : "", k + 1, FormatCount(double(s.level_triangles[k])),
                                s.stored_triangles ? 100.0 * double(s.level_triangles[k]) /
                                                         double(s.stored_triangles)
                                                   : 0.0,
                                FormatBytes(s.level_bytes[k]));
        }
        const uint64_t without = s.output_bytes - std::min(level_bytes, s.output_bytes);
        out += fmt::format(
            "\nlevels:      {}; {:+.2f} % on disk; simplifying took {} of thread time ({:.0f} % of "
            "the encode threads')",
            each, without ? 100.0 * double(level_bytes) / double(without) : 0.0,
            FormatDuration(s.simplify_seconds),
            s.encode_seconds > 0
                ? 100.0 * s.simplify_seconds / (s.encode_seconds * std::max(s.threads, 1))
                : 0.0);
    } else if (s.simplify_seconds > 0) {
        out += fmt::format(
            "\nlevels:      none: no brick simplified far enough (simplifying took {} of thread "
            "time)",
            FormatDuration(s.simplify_seconds));
    } else {
        out += "\nlevels:      none";
    }
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
    if (!s.medium_grid.empty()) {
        out += fmt::format(
            "\nmedium:      grid '{}' of {}: {} voxels stored in {} bricks ({} without triangles), "
            "{}, largest density {:.6g}; {} of the grid's {} voxels dropped outside the model's "
            "box; the cut held at most {}",
            s.medium_grid, s.medium_file, FormatCount(double(s.medium_stored_voxels)),
            s.medium_bricks, s.medium_only_bricks, FormatBytes(s.medium_bytes),
            s.medium_max_density, FormatCount(double(s.medium_dropped_voxels)),
            FormatCount(double(s.medium_voxels)), FormatBytes(s.medium_cut_peak_bytes));
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
