#include "render/texture/surface_textures.h"

#include <atomic>

#include "core/log.h"
#include "core/rgb_to_spectrum.h"

namespace nave::render {

SampledSpectrum SurfaceTextures::Albedo(const std::array<float, 2>& uv,
                                        const TextureFootprint& footprint,
                                        const SampledWavelengths& lambda) const {
    float rgb[3] = {0.5f, 0.5f, 0.5f};
    float s = uv[0], t = albedo_top_left ? uv[1] : 1.f - uv[1];
    Status st = cache->Lookup(albedo, s, t, footprint, 0, 3, rgb);
    if (!st.ok()) {
        static std::atomic<bool> logged{false};
        if (!logged.exchange(true)) log::Warning("{} (texture shown as grey 0.5)", st.ToString());
        rgb[0] = rgb[1] = rgb[2] = 0.5f;
    }
    if (cache->info(albedo).channels == 1) rgb[1] = rgb[2] = rgb[0];
    return UpliftReflectance(Vec3f(rgb[0], rgb[1], rgb[2])).Sample(lambda);
}

std::shared_ptr<const SurfaceTextures> OpenSurfaceTextures(TextureCache& cache,
                                                           const store::MaterialRecord& record,
                                                           const std::filesystem::path& base_dir,
                                                           std::vector<std::string>* warnings) {
    auto it = record.textures.find("map_Kd");
    bool top_left = false;
    if (it == record.textures.end()) {
        it = record.textures.find("baseColorTexture");
        top_left = true;
    }
    if (it == record.textures.end()) return nullptr;
    StatusOr<TextureRef> ref = cache.Open(base_dir / it->second);
    if (!ref.ok()) {
        warnings->push_back(fmt::format("material {}: {}; its flat colour is used", record.name,
                                        ref.status().ToString()));
        return nullptr;
    }
    auto t = std::make_shared<SurfaceTextures>();
    t->cache = &cache;
    t->albedo = *ref;
    t->albedo_top_left = top_left;
    return t;
}

}  // namespace nave::render
