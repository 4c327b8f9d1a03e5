// A `.vdb` file, as `nave preprocess` and `[medium] grid` read one, and the pieces a store holds:
// the input is written to a file, read whole (VdbPlugin::ReadScalarGrid) and cut along two boxes
// (CutScalarGrid); each piece is read back from its bytes (ReadScalarGridBytes, as the renderer
// and `nave verify` read a store's pieces), and so are the input's own bytes. Every grid that
// reads is marched once along its box's diagonal, as a ray would be. OpenVDB's reader leaks a
// buffer when it gives up on bytes that are not its format (tests/lsan.supp).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <string_view>

#include "fuzz_file.h"
#include "src/volumes/vdb_plugin.h"

namespace {

using nave::volumes::ScalarGrid;

void MarchDiagonal(const ScalarGrid& grid) {
    const nave::Bounds3f box = grid.bounds();
    if (box.Empty() || !nave::IsFinite(box.min) || !nave::IsFinite(box.max)) return;
    const nave::Vec3f diagonal = box.max - box.min;
    const float length = nave::Length(diagonal);
    if (!(length > 0) || !std::isfinite(length)) return;
    // A grid may hold millions of voxels along a line: a few thousand are enough to exercise it.
    int visits = 0;
    grid.March(box.min, diagonal / length, 0, length,
               [&](float, float, float) { return ++visits < 4096; });
}

void ReadPiece(const nave::volumes::VdbPlugin& plugin, std::span<const std::byte> bytes) {
    auto grid = plugin.ReadScalarGridBytes(bytes, "fuzz piece");
    if (grid.ok()) MarchDiagonal(**grid);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const nave::volumes::VdbPlugin* plugin = [] {
        auto loaded = nave::volumes::LoadVdbPlugin();
        if (!loaded.ok()) std::abort();  // a build without the plugin fuzzes nothing
        return *loaded;
    }();
    const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
    ReadPiece(*plugin, bytes);
    const auto file = nave::fuzz::WriteInput(
        "input.vdb", std::string_view(reinterpret_cast<const char*>(data), size));
    if (auto whole = plugin->ReadScalarGrid(file, "density"); whole.ok()) MarchDiagonal(**whole);
    // The dust of `nave generate dust` lies over [0, 56] x [-13, 13] x [0, 20] m: two boxes across
    // it, and one beside it.
    const nave::Bounds3f boxes[] = {{{-100, -100, -100}, {28, 100, 100}},
                                    {{28, -100, -100}, {100, 100, 100}},
                                    {{500, 500, 500}, {501, 501, 501}}};
    (void)plugin->CutScalarGrid(file, "density", boxes, /*memory_limit=*/0,
                                [&](size_t, nave::volumes::GridPiece piece) {
                                    ReadPiece(*plugin, piece.bytes);
                                    return nave::Status::Ok();
                                });
    return 0;
}
