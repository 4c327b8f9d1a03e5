// A brick's piece of a medium as a store holds it: OpenVDB's serialization of one float grid, read
// by the OpenVDB plugin's ReadScalarGridBytes as `nave verify` and the renderer read it. A grid
// that reads is marched once along its box's diagonal, as a ray would be. OpenVDB's reader leaks a
// buffer when it gives up on bytes that are not its format (tests/lsan.supp).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "src/volumes/vdb_plugin.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const nave::volumes::VdbPlugin* plugin = [] {
        auto loaded = nave::volumes::LoadVdbPlugin();
        if (!loaded.ok()) std::abort();  // a build without the plugin fuzzes nothing
        return *loaded;
    }();
    auto grid = plugin->ReadScalarGridBytes(
        std::span<const std::byte>(reinterpret_cast<const std::byte*>(data), size), "fuzz input");
    if (!grid.ok()) return 0;
    const nave::Bounds3f box = (*grid)->bounds();
    if (box.Empty() || !nave::IsFinite(box.min) || !nave::IsFinite(box.max)) return 0;
    const nave::Vec3f diagonal = box.max - box.min;
    const float length = nave::Length(diagonal);
    if (!(length > 0) || !std::isfinite(length)) return 0;
    // A grid may hold millions of voxels along a line: a few thousand are enough to exercise it.
    int visits = 0;
    (*grid)->March(box.min, diagonal / length, 0, length,
                   [&](float, float, float) { return ++visits < 4096; });
    return 0;
}
