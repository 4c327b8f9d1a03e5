#include "src/render/scene/texture/surface_textures.h"

#include <atomic>

#include "src/core/log.h"
#include "src/core/rgb_to_spectrum.h"

namespace nave::render {
namespace {

/// Looks up `n` channels from `first` at uv (flipping t for bottom-left origins); on failure logs
/// once and leaves `out` as it was (the caller's neutral value).
void Lookup(const TextureCache& cache, TextureRef ref, bool top_left,
            const std::array<float, 2>& uv, const TextureFootprint& footprint, int first, int n,
            float* out) {
    const float s = uv[0], t = top_left ? uv[1] : 1.f - uv[1];
    Status st = cache.Lookup(ref, s, t, footprint, first, n, out);
    if (!st.ok()) {
        static std::atomic<bool> logged{false};
        if (!logged.exchange(true))
            log::Warning("{} (a neutral value is used instead)", st.ToString());
    }
}

/// Reads RGB, spreading a single grey channel over all three.
Vec3f LookupRgb(const TextureCache& cache, TextureRef ref, bool top_left,
                const std::array<float, 2>& uv, const TextureFootprint& footprint, float neutral) {
    float rgb[3] = {neutral, neutral, neutral};
    Lookup(cache, ref, top_left, uv, footprint, 0, 3, rgb);
    if (cache.info(ref).channels < 3) rgb[1] = rgb[2] = rgb[0];
    return Vec3f(rgb[0], rgb[1], rgb[2]);
}

/// glTF slots have their texture origin top-left; OBJ/MTL slots (map_*, bump, norm) bottom-left.
bool TopLeft(const std::string& slot) {
    return slot.rfind("map_", 0) != 0 && slot != "bump" && slot != "norm" && slot != "disp";
}

}  // namespace

SampledSpectrum SurfaceTextures::Albedo(const std::array<float, 2>& uv,
                                        const TextureFootprint& footprint,
                                        const SampledWavelengths& lambda) const {
    Vec3f rgb = LookupRgb(*cache, albedo, albedo_top_left, uv, footprint, 0.5f);
    return UpliftReflectance(rgb).Sample(lambda);
}

SampledSpectrum SurfaceTextures::Emission(const std::array<float, 2>& uv,
                                          const SampledWavelengths& lambda) const {
    Vec3f rgb = LookupRgb(*cache, emission, emission_top_left, uv, TextureFootprint{}, 0.f) *
                emission_factor;
    return RgbEmission(rgb).Sample(lambda) * emission_scale;
}

SampledSpectrum SurfaceTextures::MeanEmission(const SampledWavelengths& lambda) const {
    // A footprint of the whole texture selects the coarsest MIP level: the mean over the image.
    Vec3f rgb = LookupRgb(*cache, emission, emission_top_left, {0.5f, 0.5f},
                          TextureFootprint::Isotropic(1.f), 0.f) *
                emission_factor;
    return RgbEmission(rgb).Sample(lambda) * emission_scale;
}

SampledSpectrum SurfaceTextures::Transmittance(const std::array<float, 2>& uv,
                                               const SampledWavelengths& lambda) const {
    const float s = uv[0], t = transmittance_top_left ? uv[1] : 1.f - uv[1];
    StatusOr<SampledSpectrum> tau = transmittance->Sample(s, t, TextureFootprint{}, lambda);
    if (!tau.ok()) {
        static std::atomic<bool> logged{false};
        if (!logged.exchange(true))
            log::Warning("{} (clear glass is used instead)", tau.status().ToString());
        return SampledSpectrum(1.f);
    }
    return *tau;
}

bool SurfaceTextures::Present(const std::array<float, 2>& uv) const {
    if (!alpha) return true;
    float a = 1.f;
    Lookup(*cache, alpha, alpha_top_left, uv, TextureFootprint{}, alpha_channel, 1, &a);
    return a * alpha_factor >= alpha_cutoff;
}

std::shared_ptr<const SurfaceTextures> OpenSurfaceTextures(TextureCache& cache,
                                                           const store::MaterialRecord& record,
                                                           const std::filesystem::path& base_dir,
                                                           const SurfaceTextureOptions& options,
                                                           std::vector<std::string>* warnings) {
    auto t = std::make_shared<SurfaceTextures>();
    t->cache = &cache;
    // The first slot of `slots` the record has, opened; empty if none or if it cannot be opened.
    auto open = [&](std::initializer_list<const char*> slots, bool* top_left) -> TextureRef {
        for (const char* slot : slots) {
            auto it = record.textures.find(slot);
            if (it == record.textures.end()) continue;
            StatusOr<TextureRef> ref = cache.Open(base_dir / it->second);
            if (!ref.ok()) {
                warnings->push_back(fmt::format("material {}: {}: {}; its flat value is used",
                                                record.name, slot, ref.status().ToString()));
                return {};
            }
            *top_left = TopLeft(slot);
            return *ref;
        }
        return {};
    };
    if (options.use_albedo) t->albedo = open({"map_Kd", "baseColorTexture"}, &t->albedo_top_left);
    t->alpha = open({"map_d", "alphaMask"}, &t->alpha_top_left);
    if (t->alpha) {
        const int channels = cache.info(t->alpha).channels;
        // RGBA images keep alpha in channel 3; a mask image (map_d) is grey: its first channel.
        t->alpha_channel = channels >= 4 ? 3 : 0;
        t->alpha_cutoff = record.alpha_cutoff;
        // glTF: alpha = texel alpha x baseColorFactor alpha (glTF 2.0 §3.9.2); MTL map_d is the
        // dissolve itself.
        t->alpha_factor = record.textures.count("alphaMask") ? record.opacity : 1.f;
        // An RGB image named as a glTF alpha source has no alpha channel: the surface is opaque.
        if (record.textures.count("alphaMask") && channels < 4) t->alpha = {};
    }
    if (options.use_emission)
        t->emission = open({"map_Ke", "emissiveTexture"}, &t->emission_top_left);
    if (options.use_transmittance) {
        if (auto it = record.textures.find("nave:transmittance"); it != record.textures.end()) {
            StatusOr<SpectralTexture> tex = SpectralTexture::Open(cache, base_dir / it->second);
            if (tex.ok()) {
                t->transmittance = std::move(tex).value();
                t->transmittance_top_left =
                    true;  // written by nave: image rows from the top, t = v
            } else {
                warnings->push_back(
                    fmt::format("material {}: nave:transmittance: {}; its flat value is used",
                                record.name, tex.status().ToString()));
            }
        }
    }
    t->emission_scale = options.emission_scale;
    // MTL Ke and glTF emissiveFactor multiply the texture; exporters often leave Ke at 0 beside a
    // map_Ke, which would switch the texture off, so an all-zero factor counts as 1.
    const auto& f = record.emission;
    if (f[0] > 0.f || f[1] > 0.f || f[2] > 0.f) t->emission_factor = Vec3f(f[0], f[1], f[2]);
    if (!t->albedo && !t->alpha && !t->emission && !t->transmittance) return nullptr;
    return t;
}

}  // namespace nave::render
