#pragma once
// Opening a model and pulling every triangle out of it, as the partitioner does: the fuzz targets
// of the importers run this and accept any Status, but not a crash, a sanitizer report or a
// triangle the importer's own checks should have dropped.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::fuzz {

/// Reads `source` to its end in small batches (so batch boundaries are exercised too); aborts if a
/// triangle is non-finite or names a material outside the table.
inline void Drain(StatusOr<std::unique_ptr<preprocess::TriangleSource>> opened) {
    if (!opened.ok()) return;
    preprocess::TriangleSource& source = **opened;
    std::vector<preprocess::Triangle> batch;
    uint32_t max_material = 0;
    for (;;) {
        StatusOr<bool> more = source.Next(batch, 7);
        if (!more.ok() || !*more) break;
        for (const preprocess::Triangle& t : batch) {
            for (const Vec3f& p : t.p) {
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
            }
            max_material = std::max(max_material, t.material);
        }
    }
    // Materials may grow while streaming (OBJ usemtl); once drained every triangle's must exist.
    if (max_material > 0 && max_material >= source.materials().size()) std::abort();
    (void)source.warnings().Summary();
    (void)source.memory_bytes();
}

}  // namespace nave::fuzz
