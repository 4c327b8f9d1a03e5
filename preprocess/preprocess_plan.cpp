#include "preprocess/preprocess_plan.h"

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "preprocess/medium_cut.h"
#include "preprocess/partition/brick_builder.h"
#include "src/core/memory.h"

namespace nave::preprocess {

MachineResources QueryMachineResources() {
    MachineResources machine;
    machine.physical_memory_bytes = PhysicalMemoryBytes();
    machine.hardware_threads = int(std::max(1u, std::thread::hardware_concurrency()));
    rlimit files{};
    if (getrlimit(RLIMIT_NOFILE, &files) == 0) {
        machine.open_files =
            files.rlim_cur == RLIM_INFINITY ? uint64_t(1) << 20 : uint64_t(files.rlim_cur);
    }
    return machine;
}

StatusOr<PreprocessPlan> PlanPreprocess(const PreprocessOptions& options,
                                        const MachineResources& machine) {
    PreprocessPlan plan;
    for (const std::filesystem::path& input : options.inputs) {
        if (!IsMediumFile(input)) {
            plan.models.push_back(input);
        } else if (plan.medium.empty()) {
            plan.medium = input;
        } else {
            return InvalidArgumentError(
                "two media given, {} and {}: a store holds one medium grid; give one .vdb file",
                plan.medium.string(), input.string());
        }
    }
    if (plan.models.empty() == options.generate.empty()) {
        return InvalidArgumentError(
            "give either model files or --generate abbey[:detail=D], not {}{}",
            plan.models.empty() ? "neither" : "both",
            plan.medium.empty() ? "" : " (a .vdb file is a medium, not a model)");
    }
    if (!plan.medium.empty() && options.medium_grid.empty())
        return InvalidArgumentError("--medium-grid: the grid's name is empty");
    if (options.output.empty()) return InvalidArgumentError("no output file given (-o MODEL.nave)");
    if (options.brick_triangles != 0 && options.brick_triangles < kMinBrickTriangles) {
        return InvalidArgumentError("--brick-triangles {}: expected at least {}",
                                    options.brick_triangles, kMinBrickTriangles);
    }
    if (options.precision < 0)
        return InvalidArgumentError("--precision {}: must be positive", options.precision);

    plan.threads = options.threads > 0 ? options.threads : std::max(1, machine.hardware_threads);
    plan.memory_budget =
        options.memory_bytes > 0 ? options.memory_bytes : machine.physical_memory_bytes / 4;

    // The budget must hold one brick's work (the largest a leaf may be: LeafMaxTriangles, 5/4 of
    // the target, hence 4/5 of what fits). Without --brick-triangles, bricks get the default size,
    // or the largest whose work fits the budget.
    const uint64_t fit = plan.memory_budget > kFixedBytes
                             ? (plan.memory_budget - kFixedBytes) / kEncodeBytesPerTriangle * 4 / 5
                             : 0;
    plan.brick_triangles = options.brick_triangles;
    if (plan.brick_triangles == 0) {
        plan.brick_triangles =
            std::clamp<uint64_t>(fit, kMinBrickTriangles, kDefaultBrickTriangles);
        plan.brick_triangles_fitted = plan.brick_triangles < kDefaultBrickTriangles;
    }
    plan.leaf_max_triangles = LeafMaxTriangles(plan.brick_triangles);
    plan.brick_work_bytes = plan.leaf_max_triangles * kEncodeBytesPerTriangle;
    if (plan.memory_budget < kFixedBytes + plan.brick_work_bytes) {
        return ResourceExhaustedError(
            "--memory {} cannot hold the work for one brick: {} triangles x {} bytes = {} plus {} "
            "fixed; raise --memory to at least {} or lower --brick-triangles to at most {}",
            FormatBytes(plan.memory_budget), plan.leaf_max_triangles, kEncodeBytesPerTriangle,
            FormatBytes(plan.brick_work_bytes), FormatBytes(kFixedBytes),
            FormatBytes(kFixedBytes + plan.brick_work_bytes), fit);
    }

    // One producer (7-13 M triangles/s) outruns the whole preprocess (about 1 M/s) anyway; a second
    // one only shortens the read phase, so it is left out of small budgets.
    plan.generator_producers = plan.memory_budget >= (uint64_t(1) << 30) ? plan.threads : 1;

    // A sixteenth of the budget for the split's block buffers, and as many leaves per pass as they
    // and the open-file limit allow.
    plan.partition.brick_triangles = plan.brick_triangles;
    plan.partition.threads = plan.threads;
    plan.partition.split_buffer_bytes = plan.memory_budget / 16;
    plan.partition.block_bytes =
        std::clamp<uint64_t>(plan.partition.split_buffer_bytes / (64 * 2), 16 << 10, 256 << 10);
    plan.partition.max_fanout =
        MaxSplitFanout(plan.partition.split_buffer_bytes, machine.open_files);

    plan.temp_parent = !options.temp_dir.empty()          ? options.temp_dir
                       : options.output.has_parent_path() ? options.output.parent_path()
                                                          : std::filesystem::path(".");
    return plan;
}

StatusOr<uint64_t> PlanTextureReserve(const PreprocessPlan& plan) {
    const uint64_t need = kFixedBytes + plan.brick_work_bytes + kTextureConversionBytes;
    if (plan.memory_budget < need) {
        return ResourceExhaustedError(
            "--memory {} cannot hold texture conversion ({} for OpenImageIO) beside the work for "
            "one brick ({}): raise --memory to at least {}, or pass --no-textures to store flat "
            "colours only",
            FormatBytes(plan.memory_budget), FormatBytes(kTextureConversionBytes),
            FormatBytes(need - kTextureConversionBytes), FormatBytes(need));
    }
    return kTextureConversionBytes;
}

StatusOr<GridPlan> PlanGrid(double precision, const Bounds3d& bounds) {
    GridPlan plan;
    const double step =
        precision > 0 ? precision : DefaultGridStep(Length(bounds.max - bounds.min));
    plan.max_error = step * std::sqrt(3.0) / 2;
    const double extent = std::max(
        {bounds.max.x - bounds.min.x, bounds.max.y - bounds.min.y, bounds.max.z - bounds.min.z});
    if (extent / step > double(1 << 29)) {
        return InvalidArgumentError(
            "--precision {}: the model is {} units across, {} grid steps; at most 2^29 fit: use "
            "--precision {} or more",
            step, extent, extent / step, extent / double(1 << 29));
    }
    plan.grid.origin = bounds.min;
    plan.grid.step = step;
    plan.root = Bounds3f(Vec3f(bounds.min) - Vec3f(1, 1, 1) * float(step),
                         Vec3f(bounds.max) + Vec3f(1, 1, 1) * float(step));
    return plan;
}

StatusOr<EncodePlan> PlanEncode(const PreprocessPlan& plan, uint64_t texture_reserve,
                                const std::vector<LeafBin>& leaves) {
    // Each encoding thread keeps its buffers (sized by the largest brick it met), so the budget
    // bounds the number of encoding threads.
    EncodePlan encode;
    encode.budget = plan.memory_budget - kFixedBytes - texture_reserve;
    for (const LeafBin& leaf : leaves)
        encode.largest_leaf = std::max(encode.largest_leaf, leaf.triangles);
    encode.threads = int(std::clamp<uint64_t>(
        encode.budget / std::max<uint64_t>(1, encode.largest_leaf * kEncodeBytesPerTriangle), 1,
        uint64_t(plan.threads)));
    for (const LeafBin& leaf : leaves) {
        const uint64_t need = leaf.triangles * kEncodeBytesPerTriangle;
        if (need > encode.budget) {
            return ResourceExhaustedError(
                "a brick of {} triangles (cell {} could not be split further: its triangles "
                "overlap) needs {} to encode, more than --memory {} allows; raise --memory to at "
                "least {}",
                leaf.triangles, fmt::streamed(leaf.cell), FormatBytes(need),
                FormatBytes(plan.memory_budget), FormatBytes(need + kFixedBytes + texture_reserve));
        }
    }
    return encode;
}

}  // namespace nave::preprocess
