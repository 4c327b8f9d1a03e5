#pragma once
// Small STEP and IGES files written with Open CASCADE for the CAD import tests: nave's own
// fixtures, made where they are used rather than checked in.

#include <filesystem>
#include <string>

namespace nave::preprocess::testing {

/// The test chapel, in metres: an "Altar" box 1 x 2 x 0.5 at the origin, red (0.8, 0.1, 0.1), and a
/// "Column" cylinder of radius 0.1 and height 1 along z, placed twice: at (5, 0, 0) and (0, 5, 0),
/// under an assembly "Chapel". Lengths are written in `unit` ("MM", "M", "INCH"), the file's own
/// length unit.
constexpr double kColumnRadius = 0.1;

/// Writes the chapel as a STEP (AP214) file. False when Open CASCADE fails to write it.
bool WriteChapelStep(const std::filesystem::path& path, const std::string& unit = "MM");
/// Writes the chapel as an IGES file (IGES has no assemblies: Open CASCADE flattens them), in
/// millimetres.
bool WriteChapelIges(const std::filesystem::path& path);

}  // namespace nave::preprocess::testing
