#include "preprocess/medium_cut.h"

#include <fmt/ostream.h>

#include <algorithm>
#include <cctype>

#include "preprocess/import/file_extension.h"
#include "src/core/log.h"
#include "src/core/progress.h"
#include "src/volumes/vdb_plugin.h"

namespace nave::preprocess {
namespace {

/// The plugin reports a grid it cannot use as InvalidArgument, as a render config naming a bad
/// grid is. Given to preprocess, the .vdb is input data, and bad data ends a run with exit code 1.
Status AsBadData(Status status) {
    if (status.code() != StatusCode::kInvalidArgument) return status;
    return Status(StatusCode::kDataLoss, status.message());
}

}  // namespace

bool IsMediumFile(const std::filesystem::path& path) { return LowerExtension(path) == ".vdb"; }

Status CheckMediumGrid(const std::filesystem::path& file, const std::string& grid,
                       uint64_t memory_budget) {
    NAVE_ASSIGN_OR_RETURN(const volumes::VdbPlugin* plugin, volumes::LoadVdbPlugin());
    // No boxes: the plugin checks the file, the grid's type and transform, and counts its voxels.
    return AsBadData(
        plugin
            ->CutScalarGrid(file, grid, {}, memory_budget,
                            [](size_t, const volumes::GridPiece&) { return Status::Ok(); })
            .status());
}

Status StoreMedium(const std::filesystem::path& file, const std::string& grid, const Bounds3f& root,
                   uint64_t memory_budget, std::vector<store::BrickTreeNode>& nodes,
                   store::StoreWriter& writer, PreprocessStats* stats) {
    NAVE_ASSIGN_OR_RETURN(const volumes::VdbPlugin* plugin, volumes::LoadVdbPlugin());
    NAVE_RETURN_IF_ERROR(writer.SetMediumGrid(grid));
    // Every leaf, a brick's or an empty one: the medium fills space the surfaces leave empty too.
    const std::vector<std::pair<uint32_t, Bounds3f>> leaves =
        store::BrickTree(root, nodes).LeafCells();
    std::vector<Bounds3f> cells;
    cells.reserve(leaves.size());
    for (const auto& leaf : leaves) cells.push_back(leaf.second);

    stats->medium_file = file.string();
    stats->medium_grid = grid;
    ProgressBar bar("medium", 0, "pieces");
    auto store_piece = [&](size_t i, volumes::GridPiece piece) -> Status {
        bar.Add(1);
        store::BrickTreeNode& node = nodes[leaves[i].first];
        if (node.brick == store::kNoBrick) {
            // A cell with medium and no surface: a brick of no triangles, so that rays visit it.
            NAVE_ASSIGN_OR_RETURN(node.brick, writer.Append(store::EmptyBrick(cells[i])));
            ++stats->medium_only_bricks;
        }
        store::EncodedMedium medium;
        medium.grid_bytes = std::move(piece.bytes);
        medium.active_voxels = piece.active_voxels;
        medium.max_density = piece.max_value;
        medium.decoded_bytes = piece.memory_bytes;
        NAVE_RETURN_IF_ERROR(writer.AppendMedium(node.brick, medium));
        ++stats->medium_bricks;
        stats->medium_stored_voxels += medium.active_voxels;
        stats->medium_bytes += medium.grid_bytes.size();
        stats->medium_max_density = std::max(stats->medium_max_density, medium.max_density);
        return Status::Ok();
    };
    auto summary = plugin->CutScalarGrid(file, grid, cells, memory_budget, store_piece);
    if (!summary.ok()) return AsBadData(summary.status());
    bar.Finish();
    stats->medium_voxels = summary->active_voxels;
    stats->medium_cut_peak_bytes = summary->peak_bytes;
    stats->medium_dropped_voxels = summary->voxels_outside;
    if (summary->voxels_outside > 0) {
        const std::string warning = fmt::format(
            "{}: grid '{}': {} of its {} voxels lie outside the model's box {} and were dropped",
            file.string(), grid, summary->voxels_outside, summary->active_voxels,
            fmt::streamed(root));
        log::Warning("{}", warning);
        stats->warnings.push_back(warning);
    }
    return Status::Ok();
}

}  // namespace nave::preprocess
