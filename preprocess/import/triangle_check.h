#pragma once
// The checks every importer applies to a triangle before passing it on: finite coordinates and a
// non-zero area. A failing triangle is skipped and counted (the model stays usable).

#include <string>

#include "preprocess/import_warnings.h"
#include "preprocess/triangle_source.h"

namespace nave::preprocess {

inline constexpr const char* kWarnDegenerate =
    "degenerate faces skipped (zero area or repeated vertex)";
inline constexpr const char* kWarnNonFinite = "faces with NaN or infinite coordinates skipped";

/// True if `t` can be used; otherwise counts a warning at `where` and returns false.
inline bool AcceptTriangle(const Triangle& t, ImportWarnings& warnings, const std::string& where) {
    if (!IsFinite(t.p[0]) || !IsFinite(t.p[1]) || !IsFinite(t.p[2])) {
        warnings.Add(kWarnNonFinite, where);
        return false;
    }
    Vec3d a(t.p[0]), b(t.p[1]), c(t.p[2]);
    Vec3d n = Cross(b - a, c - a);
    if (Dot(n, n) == 0.0) {
        warnings.Add(kWarnDegenerate, where);
        return false;
    }
    return true;
}

}  // namespace nave::preprocess
