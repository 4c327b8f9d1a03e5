#include "src/imaging/texture_cache.h"

#include <algorithm>
#include <cmath>

#include "src/imaging/oiio_plugin.h"

namespace nave::imaging {

TextureFootprint RayConeFootprint(float cone_width_m, float cos_theta, float uv_area,
                                  float world_area_m2) {
    if (!(world_area_m2 > 0.f) || !(uv_area > 0.f)) return {};
    // Ray Tracing Gems ch. 20: LOD = Δ0 + log2(|W| / |n·d|) with Δ0 = ½ log2(t_a / p_a); in
    // footprint form the width in texture units is sqrt(t_a / p_a) · |W| / |n·d|. |n·d| is kept
    // away from 0 so grazing hits filter over at most the whole texture instead of overflowing.
    float cos_abs = std::max(std::abs(cos_theta), 1e-3f);
    float width = std::sqrt(uv_area / world_area_m2) * std::abs(cone_width_m) / cos_abs;
    return TextureFootprint::Isotropic(std::min(width, 1.f));
}

StatusOr<std::unique_ptr<TextureCache>> TextureCache::Create(size_t max_memory_bytes) {
    NAVE_ASSIGN_OR_RETURN(const OiioPlugin* plugin, LoadOiioPlugin());
    return plugin->CreateTextureCache(max_memory_bytes);
}

}  // namespace nave::imaging
