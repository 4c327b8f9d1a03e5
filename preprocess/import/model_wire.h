#pragma once
// A loaded model (indexed meshes and materials) as a flat byte string, so that a child process that
// ran a crash-prone library can hand its result to nave (assimp_importer.cpp). Native byte order:
// both ends are the same executable. The decoder trusts nothing: every count is checked against the
// bytes left before anything is allocated.

#include <string>
#include <vector>

#include "preprocess/import/indexed_mesh_source.h"
#include "src/core/status.h"

namespace nave::preprocess {

/// What an in-memory importer produces.
struct ImportedModel {
    std::vector<IndexedMesh> meshes;
    std::vector<store::MaterialRecord> materials;
};

std::string EncodeImportedModel(const ImportedModel& model);

/// Errors: DataLoss naming `what` (the model file) and the byte offset where the bytes stopped
/// making sense (a child that died mid-write, or a bug).
StatusOr<ImportedModel> DecodeImportedModel(std::string_view bytes, const std::string& what);

}  // namespace nave::preprocess
