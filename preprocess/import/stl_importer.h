#pragma once
// STL, ASCII and binary, streamed: nothing is kept but the current facet. A binary file whose
// 80-byte header starts with "solid" (many exporters write that) is recognised by its size: 84 + 50
// * count bytes. Facet normals are ignored (exporters often get them wrong); the winding gives the
// front.

#include <filesystem>
#include <memory>

#include "preprocess/triangle_source.h"

namespace nave::preprocess {

StatusOr<std::unique_ptr<TriangleSource>> OpenStl(const std::filesystem::path& path);

}  // namespace nave::preprocess
