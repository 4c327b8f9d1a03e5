#pragma once
// Data files compiled into nave (data/*.csv: CIE tables, illuminants, optical constants,
// reflectances). The build turns each file into a string in a generated .cpp, so the binary never
// looks for data/ at run time. data/SOURCES.md says where each file comes from.

#include <string_view>
#include <vector>

#include "src/core/spectrum.h"

namespace nave {

/// The text of data/`name` (e.g. "cie_1931_2deg_cmf.csv") as compiled in, or an empty view if there
/// is no such file. Thread-safe; the view lives as long as the program.
std::string_view EmbeddedDataFile(std::string_view name);
/// The names of all compiled-in data files, sorted.
std::vector<std::string_view> EmbeddedDataFileNames();
/// The compiled-in CSV file `name` parsed with ParseSpectraCsv, cached. A missing or malformed file
/// is a build bug: CHECK-fails. Thread-safe; the reference lives as long as the program.
const SpectraTable& EmbeddedSpectraTable(std::string_view name);

}  // namespace nave
