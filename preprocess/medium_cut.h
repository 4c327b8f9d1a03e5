#pragma once
// A participating medium's density, an OpenVDB float grid given beside the models (`nave
// preprocess model.obj dust.vdb`), cut along the brick tree's leaves and stored brick by brick
// (store format 3.3, docs/store-format.md "Medium"). The grid is read box by box through the
// OpenVDB plugin (volumes::VdbPlugin::CutScalarGrid), never whole. docs/preprocess.md, "Media".

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "preprocess/preprocess.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "store/brick_tree.h"
#include "store/store_writer.h"

namespace nave::preprocess {

/// Whether `path` names a medium (a .vdb file, whatever the case of its extension) rather than a
/// model.
bool IsMediumFile(const std::filesystem::path& path);

/// Checks that `file` is an OpenVDB file holding a float grid named `grid` whose transform a
/// medium can use, before the run reads any model (the values are checked as they are cut), and
/// that cutting it can fit `memory_budget` (its topology twice: volumes::VdbPlugin::CutScalarGrid).
/// Errors name the file and the grid: NotFound for a missing file, DataLoss for a file that is not
/// OpenVDB or is cut short, a missing grid (listing the grids there) or another value type,
/// ResourceExhausted for a grid too large for the budget.
Status CheckMediumGrid(const std::filesystem::path& file, const std::string& grid,
                       uint64_t memory_budget);

/// Cuts grid `grid` of `file` along every leaf cell of the tree (`root`, `nodes`), appends each
/// piece to the brick of its leaf (a leaf without a brick gets one without triangles, and
/// `nodes` names it), and records the grid in the store (StoreWriter::SetMediumGrid). Voxels
/// outside `root` are dropped and counted. Fills the medium fields of `stats` and warns of dropped
/// voxels. What the cut holds at once stays within `memory_budget` (the bricks are encoded and
/// their memory freed by then): a leaf whose piece would not fit is ResourceExhausted naming it.
/// Errors as CheckMediumGrid's, and DataLoss for a negative or non-finite density (naming the
/// voxel).
Status StoreMedium(const std::filesystem::path& file, const std::string& grid, const Bounds3f& root,
                   uint64_t memory_budget, std::vector<store::BrickTreeNode>& nodes,
                   store::StoreWriter& writer, PreprocessStats* stats);

}  // namespace nave::preprocess
