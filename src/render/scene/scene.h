#pragma once
// A scene ready to render: the config resolved against a model. Material names of the model are
// mapped to spectral materials (a name with no mapping is an error naming it, unless a "default"
// mapping exists), config spectra are tabulated, and the sun's direction and spectrum are computed
// from date and place.

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "src/core/sampling.h"
#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/bricks/brick_source.h"
#include "src/render/scene/camera.h"
#include "src/render/scene/lights/light.h"
#include "src/render/scene/lights/sky_light.h"
#include "src/render/scene/lights/sun_light.h"
#include "src/render/scene/materials/bxdf.h"
#include "src/render/scene/materials/frame.h"
#include "src/render/scene/materials/materials.h"
#include "src/render/scene/media/medium.h"
#include "src/render/scene/media/medium_index.h"
#include "src/render/scene/scene_config.h"
#include "src/render/scene/sun/sky.h"
#include "src/render/scene/texture/surface_textures.h"

namespace nave::render {

/// A spectral material as the integrators use it: the physics library's Material
/// (render/scene/materials/ materials.h) plus what the scene adds: emission, the portal flag, and
/// black (absorbs everything).
struct SurfaceMaterial {
    std::string name;
    Material material;   ///< physics: diffuse, conductor, dielectric, thin glass
    bool black = false;  ///< no scattering at all
    bool emissive = false;
    Spectrum emission;    ///< radiance, W m^-2 sr^-1 nm^-1, both sides
    bool portal = false;  ///< photons are aimed at it (render.photon_target = "portals")
    /// A solid dielectric's inside (RenderScene::MediumOf: kClearSolid, or its medium table's);
    /// kOutsideMedium for a surface with no inside (any other material, thin glass included).
    uint8_t medium_inside = kOutsideMedium;
    /// The model's textures for this material (albedo of a diffuse material, alpha, emission);
    /// null: none.
    std::shared_ptr<const SurfaceTextures> textures;

    /// The BSDF at a hit with unit shading normal `ns`. Dispersive refraction terminates the
    /// secondary wavelengths of `lambda`.
    Bsdf MakeBsdf(const Vec3f& ns, SampledWavelengths* lambda) const {
        if (black) return Bsdf(ns, Vec3f(0, 0, 0), Bxdf());
        return Bsdf(ns, Vec3f(0, 0, 0), GetBxdf(material, *lambda));
    }
    /// The BSDF at a hit with texture coordinates `uv` (null when the mesh has none), textures
    /// filtered over `footprint`.
    Bsdf MakeBsdf(const Vec3f& ns, SampledWavelengths* lambda, const std::array<float, 2>* uv,
                  const TextureFootprint& footprint = {}) const {
        if (textures && textures->albedo && uv != nullptr && !black &&
            std::holds_alternative<DiffuseMaterial>(material))
            return Bsdf(ns, Vec3f(0, 0, 0),
                        Bxdf(DiffuseBxdf(textures->Albedo(*uv, footprint, *lambda))));
        if (const ThinGlassMaterial* glass = thin_glass();
            glass && textures && textures->transmittance && uv) {
            SampledSpectrum tau = textures->Transmittance(*uv, *lambda);
            return Bsdf(ns, Vec3f(0, 0, 0), glass->GetBxdf(*lambda, &tau));
        }
        return MakeBsdf(ns, lambda);
    }
    /// The internal transmittance of a thin glass pane at a hit with texture coordinates `uv` (null
    /// when the mesh has none): the spectral transmittance texture's where there is one. Call only
    /// on thin glass.
    SampledSpectrum GlassInternalTransmittance(const std::array<float, 2>* uv,
                                               const SampledWavelengths& lambda) const {
        if (textures && textures->transmittance && uv != nullptr)
            return textures->Transmittance(*uv, lambda);
        return thin_glass()->internal_transmittance.Sample(lambda);
    }
    /// Radiance emitted at a hit with texture coordinates `uv` (null when the mesh has none): the
    /// emission texture's where there is one, else the config's spectrum. Call only when
    /// `emissive`.
    SampledSpectrum Emitted(const std::array<float, 2>* uv,
                            const SampledWavelengths& lambda) const {
        if (textures && textures->emission) {
            return uv != nullptr ? textures->Emission(*uv, lambda) : textures->MeanEmission(lambda);
        }
        return emission.Sample(lambda);
    }
    /// Solid glass that absorbs (a dielectric with an absorption coefficient), else null.
    const DielectricMaterial* absorbing_dielectric() const {
        const DielectricMaterial* d = black ? nullptr : std::get_if<DielectricMaterial>(&material);
        return d != nullptr && d->absorption_per_m.MaxValue() > 0 ? d : nullptr;
    }
    /// The window pane, if this is thin glass (rays cross it without bending).
    const ThinGlassMaterial* thin_glass() const {
        return black ? nullptr : std::get_if<ThinGlassMaterial>(&material);
    }
    /// Whether this is solid glass whose index varies with wavelength (a path through it keeps only
    /// its hero wavelength).
    bool dispersive() const {
        const DielectricMaterial* d = black ? nullptr : std::get_if<DielectricMaterial>(&material);
        return d != nullptr && d->IsDispersive();
    }
    /// Diffuse albedo at 550 nm for the albedo AOV (1 for specular materials, 0 for black).
    float AlbedoForAov() const;
    /// Whether a specular bounce here bends or mirrors light into caustics: smooth solid glass and
    /// smooth metal. Thin glass does not: light passes through a pane unbent, and the faint image
    /// it mirrors is left to the paths that find it.
    bool MakesCaustics() const;
};

struct RenderScene {
    BrickSource* source = nullptr;
    std::unique_ptr<Camera> camera;
    std::vector<SurfaceMaterial> materials;  ///< indexed by the store's material id
    /// The lights next-event estimation samples, in this order: the sun, then the config's
    /// [[lights]] (MakeLight). A light's index keys its random dimensions.
    std::vector<std::unique_ptr<Light>> lights;
    int sun = -1;  ///< index of the sun in `lights`, or -1
    /// The sun; only when `sun` >= 0.
    const SunLight& sun_light() const { return static_cast<const SunLight&>(*lights[size_t(sun)]); }
    std::unique_ptr<SkyLight> sky;  ///< uniform or physical, or null
    /// The medium filling the air ([medium]), or null.
    std::shared_ptr<const Medium> medium;
    /// The insides of solid dielectrics (SurfaceMaterial::medium_inside - kClearSolid indexes it):
    /// first null, the inside of clear solids, then one medium per material table with a medium.
    std::vector<std::shared_ptr<const Medium>> inside_media;
    /// The medium of a ray's RayRecord::medium `index`: the air's or a solid's inside (null: none
    /// there).
    const Medium* MediumOf(uint8_t index) const {
        return index == kOutsideMedium ? medium.get() : inside_media[index - kClearSolid].get();
    }
    /// Whether any ray meets a medium anywhere: the air's, or inside a solid.
    bool HasMedia() const {
        return medium != nullptr || std::any_of(inside_media.begin(), inside_media.end(),
                                                [](const auto& m) { return m != nullptr; });
    }
    RenderSettings settings;
    OutputConfig output;
    std::string sun_description;  ///< "azimuth 92.1 deg, elevation 31.4 deg" for the summary
};

/// Resolves `config` against the model in `source`.
StatusOr<RenderScene> BuildRenderScene(const SceneConfig& config, BrickSource& source);

/// Attaches the model's textures (config.textures.enabled, and each material's `textures` key) to
/// the materials of `scene`: albedo, emission (making the material emissive) and alpha cut-outs,
/// which are handed to the brick source, so call before any brick is loaded. Texture paths in the
/// material table are relative to `base_dir` (the store's directory). A texture that cannot be
/// opened is a warning in `warnings` and the material keeps its flat value. `cache` must outlive
/// the render.
Status AttachTextures(const SceneConfig& config, const std::filesystem::path& base_dir,
                      TextureCache& cache, RenderScene* scene, std::vector<std::string>* warnings);

/// The tabulated form of a config spectrum.
Spectrum ToSpectrum(const SpectrumSpec& spec);

/// The light of a [[lights]] table of the config: the factory of the lights the config lists.
std::unique_ptr<Light> MakeLight(const LightConfig& config);

/// The sun's position and spectrum for a place and time: the physics sun model (NREL SPA, clear-sky
/// transmittance, render/scene/sun/sun.h), or the config's fixed direction and spectrum.
struct SunState {
    Vec3f to_sun;  ///< unit vector, world frame (+X east, +Y north, +Z up)
    double zenith_deg = 0, azimuth_deg = 0;
    double angular_radius_rad = 0;  ///< the disc's angular radius
    Spectrum radiance;              ///< disc radiance at the ground, W m^-2 sr^-1 nm^-1
    bool above_horizon = true;
};
StatusOr<SunState> ResolveSun(const SunConfig& sun, const std::string& file);

/// The spectral irradiance (W m⁻² nm⁻¹) of `scene`'s sun and sky above the horizon on an unshadowed
/// horizontal surface facing up: the sun's L Ω cos z and the sky's ∫ L cos θ dω over the upper
/// hemisphere (π L for a uniform sky; a 64 x 128 midpoint quadrature in cos θ and φ for a physical
/// one). The light a white card on open ground reflects: the ground's under [sky] ground_albedo,
/// and the white of output.white_balance = "scene".
Spectrum HorizontalIrradiance(const RenderScene& scene);

}  // namespace nave::render
