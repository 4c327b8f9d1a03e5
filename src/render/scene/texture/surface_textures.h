#pragma once
// The textures of one surface material as the integrator uses them, resolved from the store's
// material table (MaterialRecord::textures, paths relative to the store's directory) when the scene
// is built:
//   - albedo (map_Kd, baseColorTexture): replaces a diffuse material's reflectance, lifted from RGB
//   with the
//     sigmoid-polynomial method of Jakob & Hanika 2019 (core/rgb_to_spectrum.h), at most 1
//     everywhere;
//   - alpha (map_d, glTF alphaMode MASK): cuts the surface out where alpha < the material's cutoff
//   (Embree
//     intersection filters in brick_source.cpp call Present());
//   - emission (map_Ke, emissiveTexture): lifted as an illuminant spectrum (RgbEmission);
//   - spectral transmittance ("nave:transmittance", a SpectralTexture): the internal transmittance
//   of a thin
//     glass pane per texel and wavelength band (stained glass measured band by band, as in the
//     origin paper).
// Texture coordinates follow the model: OBJ/MTL has its origin bottom-left (t = 1 - v), glTF
// top-left (t = v).

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/imaging/texture_cache.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/scene/texture/spectral_texture.h"
#include "store/material_record.h"

namespace nave::render {

using imaging::TextureCache;
using imaging::TextureFootprint;
using imaging::TextureRef;

/// The textures of one material. Immutable after construction; thread-safe. A lookup that fails (a
/// file that vanished mid-render) logs once and gives a neutral value: grey 0.5 albedo, opaque, no
/// emission.
struct SurfaceTextures final : public AlphaMask {
    const TextureCache* cache = nullptr;

    TextureRef albedo;  ///< linear RGB (or grey) albedo; empty: none
    bool albedo_top_left = false;

    TextureRef alpha;  ///< alpha source; empty: none
    bool alpha_top_left = false;
    int alpha_channel = 0;      ///< channel holding alpha (3 of RGBA, else 0)
    float alpha_factor = 1.f;   ///< multiplies the texel (glTF baseColorFactor alpha)
    float alpha_cutoff = 0.5f;  ///< present where alpha >= cutoff

    TextureRef emission;  ///< linear RGB emission; empty: none
    bool emission_top_left = false;
    float emission_scale = 1.f;  ///< luminance of the lifted spectrum per unit texel luminance
    Vec3f emission_factor{1.f, 1.f, 1.f};  ///< multiplies the texel (MTL Ke, glTF emissiveFactor)

    std::optional<SpectralTexture>
        transmittance;  ///< thin glass internal transmittance; empty: none
    bool transmittance_top_left = false;

    /// The albedo at mesh texture coordinates `uv` at the path's wavelengths (requires `albedo`).
    SampledSpectrum Albedo(const std::array<float, 2>& uv, const TextureFootprint& footprint,
                           const SampledWavelengths& lambda) const;
    /// The integrator's lookup: a point sample of the finest MIP level (the integrator tracks no
    /// ray cones yet; pixel supersampling does the filtering).
    SampledSpectrum Albedo(const std::array<float, 2>& uv, const SampledWavelengths& lambda) const {
        return Albedo(uv, TextureFootprint{}, lambda);
    }
    /// Emitted radiance at `uv` (requires `emission`), W m^-2 sr^-1 nm^-1.
    SampledSpectrum Emission(const std::array<float, 2>& uv,
                             const SampledWavelengths& lambda) const;
    /// The texture's mean emitted radiance (its coarsest MIP level), for choosing emitters by
    /// power.
    SampledSpectrum MeanEmission(const SampledWavelengths& lambda) const;
    /// Internal transmittance of a pane at `uv` (requires `transmittance`); 1 if the lookup fails.
    SampledSpectrum Transmittance(const std::array<float, 2>& uv,
                                  const SampledWavelengths& lambda) const;
    /// Whether the surface is there at `uv` (true without an alpha texture).
    bool Present(const std::array<float, 2>& uv) const override;
};

/// Options for resolving a material's textures.
struct SurfaceTextureOptions {
    bool use_albedo = true;          ///< the config material is diffuse (others keep their physics)
    bool use_transmittance = false;  ///< the config material is thin glass
    bool use_emission = true;        ///< the config gives no emission of its own
    float emission_scale = 1.f;
};

/// Opens the textures `record` names under `base_dir` in `cache`. Null when the record has none
/// that apply; a texture that cannot be opened is a warning appended to `warnings` (naming the
/// material and file) and is skipped, so the material keeps its flat colour.
std::shared_ptr<const SurfaceTextures> OpenSurfaceTextures(TextureCache& cache,
                                                           const store::MaterialRecord& record,
                                                           const std::filesystem::path& base_dir,
                                                           const SurfaceTextureOptions& options,
                                                           std::vector<std::string>* warnings);

}  // namespace nave::render
