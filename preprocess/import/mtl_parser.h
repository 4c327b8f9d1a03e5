#pragma once
// Wavefront MTL material libraries. Small files, read whole.

#include <filesystem>
#include <vector>

#include "preprocess/import_warnings.h"
#include "src/core/status.h"
#include "store/material_record.h"

namespace nave::preprocess {

/// Parses an MTL library. Texture paths are kept as written (relative to the MTL's directory); a
/// texture file that does not exist is counted as a warning (the material stays, the renderer uses
/// its colour). Unknown statements are ignored. Errors: a malformed number, naming file:line.
StatusOr<std::vector<store::MaterialRecord>> ParseMtl(const std::filesystem::path& path,
                                                      ImportWarnings& warnings);

}  // namespace nave::preprocess
