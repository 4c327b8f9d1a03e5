#pragma once
// The textures of one surface material as the integrator uses them: an albedo texture lifted to a
// spectrum per lookup (Jakob & Hanika 2019, core/rgb_to_spectrum.h). Resolved from the store's
// material table (MaterialRecord::textures, paths relative to the store's directory) at scene
// build.

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/spectrum.h"
#include "core/status.h"
#include "render/scene.h"
#include "imaging/texture_cache.h"
#include "store/material_record.h"

namespace nave::render {

using imaging::TextureCache;
using imaging::TextureFootprint;
using imaging::TextureRef;

/// Textures of one material. Immutable after construction; thread-safe. Attach it to a
/// SurfaceMaterial (albedo_texture) to replace the diffuse albedo at hits with texture coordinates.
struct SurfaceTextures : public AlbedoTexture {
    const TextureCache* cache = nullptr;
    /// Linear RGB albedo (map_Kd / baseColorTexture as converted by `nave preprocess`); replaces
    /// the diffuse albedo.
    TextureRef albedo;
    /// True when the albedo's texture coordinates are glTF's (origin top-left, t = v); MTL/OBJ
    /// coordinates have their origin bottom-left (t = 1 - v).
    bool albedo_top_left = false;

    /// The albedo at mesh texture coordinates `uv`, lifted to a reflectance at the path's
    /// wavelengths (≤ 1 everywhere). A failed lookup (a file that vanished mid-render) logs once
    /// and gives the neutral 0.5.
    SampledSpectrum Albedo(const std::array<float, 2>& uv, const TextureFootprint& footprint,
                           const SampledWavelengths& lambda) const;
    /// The integrator's lookup: a point sample of the finest MIP level (the integrator tracks no
    /// ray cones yet; pixel supersampling does the filtering).
    SampledSpectrum Albedo(const std::array<float, 2>& uv,
                           const SampledWavelengths& lambda) const override {
        return Albedo(uv, TextureFootprint{}, lambda);
    }
};

/// Opens the albedo texture named by `record` (slots "map_Kd" or "baseColorTexture") under
/// `base_dir` in `cache`. Null when the record has none; a texture that cannot be opened is a
/// warning appended to `warnings` (naming it) and null, so the material keeps its flat colour.
std::shared_ptr<const SurfaceTextures> OpenSurfaceTextures(TextureCache& cache,
                                                           const store::MaterialRecord& record,
                                                           const std::filesystem::path& base_dir,
                                                           std::vector<std::string>* warnings);

}  // namespace nave::render
