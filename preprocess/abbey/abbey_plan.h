#pragma once
// The layout of the abbey church: where every wall, pier, vault, window and roof goes. See
// docs/abbey.md for the plan, the dimensions and their sources. The church is cut into "parts" (one
// wall, one pier, one vault bay...) generated one after the other, so that the whole never has to
// be in memory.

#include <functional>
#include <string>
#include <vector>

#include "preprocess/abbey/detail.h"
#include "preprocess/abbey/emitter.h"

namespace nave::preprocess::abbey {

struct AbbeyPart {
    std::string name;  ///< "nave pier N3", for debugging
    std::function<void(Emitter&)> emit;
};

/// Every part of the abbey at `detail`, in a fixed order (deterministic output).
std::vector<AbbeyPart> AbbeyParts(const Detail& detail);

/// Whether the point (x, y) is inside the church's floor plan (nave, aisles, transept, choir,
/// ambulatory, chapels), in metres.
bool InsidePlan(double x, double y);

}  // namespace nave::preprocess::abbey
