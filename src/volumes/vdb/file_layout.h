#pragma once
// Checks of a `.vdb` file's or stream's layout made before OpenVDB reads it. OpenVDB trusts what it
// reads: the offsets of a file's grids, and every length before a string or a metadata value, for
// which it allocates (and fills) up to 4 GiB before it finds the bytes missing. These checks read
// the same structure with OpenVDB's own header reader and refuse, naming the file, any offset or
// length that reaches past the end, before OpenVDB allocates anything for it.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>

#include "src/core/status.h"

namespace nave::volumes::vdb {

/// OK if every grid of `file` lies within its bytes and the lengths in its header, its grid
/// descriptors and each grid's metadata stay within them; else InvalidArgument naming the file
/// and what reaches past the end. Lets OpenVDB's exceptions through (a file that is not OpenVDB).
Status CheckFileLayout(const std::filesystem::path& file);

/// The same for `bytes`, an io::Stream that must hold exactly one grid (a store's piece); `what`
/// names it. DataLoss on failure. Lets OpenVDB's exceptions through.
Status CheckStreamLayout(std::span<const std::byte> bytes, const std::string& what);

}  // namespace nave::volumes::vdb
