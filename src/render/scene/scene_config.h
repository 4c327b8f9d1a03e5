#pragma once
// The scene description a render reads besides the model: camera, sun, sky, lights, the mapping
// from the model's material names to spectral materials, render and output settings. Parsed from
// TOML; every key is documented in configs/README.md. Like Mitsuba's "unused parameters" check, a
// key that nothing reads is an error naming it with its file, line and column, so a misspelt key
// never passes silently.

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "src/core/color.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/scene/lights/light.h"

namespace nave::render {

/// A spectral quantity as written in a config: a constant, a table of (wavelength, value) pairs
/// linearly interpolated, or a blackbody normalised to 1 at its peak, each times `scale`.
struct SpectrumSpec {
    enum class Kind { kConstant, kTable, kBlackbody };
    Kind kind = Kind::kConstant;
    float value = 0.f;                  ///< kConstant
    std::vector<float> wavelengths_nm;  ///< kTable, increasing
    std::vector<float> values;          ///< kTable
    float temperature_k = 0.f;          ///< kBlackbody
    float scale = 1.f;
    static SpectrumSpec Constant(float v) {
        SpectrumSpec s;
        s.value = v;
        return s;
    }
    /// The value at `lambda_nm` (tables are clamped at their ends).
    float Evaluate(float lambda_nm) const;
};

struct CameraConfig {
    Vec3f position{0, 0, 0};
    Vec3f look_at{1, 0, 0};
    Vec3f up{0, 0, 1};
    float fov_deg = 60.f;  ///< vertical field of view
    int width = 640, height = 480;
    float lens_radius_m = 0.f;     ///< thin lens aperture radius; 0 is a pinhole
    float focus_distance_m = 0.f;  ///< 0: the distance to look_at
};

/// A civil date and time with its UTC offset (the sun's position needs all three).
struct DateTime {
    int year = 2025, month = 6, day = 21, hour = 12, minute = 0;
    double second = 0;
    int utc_offset_minutes = 0;
};

struct SunConfig {
    bool enabled = false;
    DateTime when;
    double latitude_deg = 0, longitude_deg = 0, elevation_m = 0;
    double pressure_mbar = 1013.25, temperature_c = 15.0;
    double turbidity = 3.0;          ///< Linke/Angstrom-style haze factor handed to the sun model
    float scale = 1.f;               ///< multiplies the sun's radiance
    std::optional<Vec3f> direction;  ///< toward the sun; overrides date/place (tests, studios)
    float angular_radius_deg =
        0.2666f;  ///< apparent radius of the disc with `direction` (the model computes its own)
    std::optional<SpectrumSpec>
        radiance;  ///< overrides the atmospheric model's spectrum (W m^-2 sr^-1 nm^-1)
};

struct SkyConfig {
    enum class Kind { kNone, kUniform, kPreetham };
    Kind kind = Kind::kNone;
    SpectrumSpec radiance;            ///< kUniform: radiance of every direction above and below
    std::optional<double> turbidity;  ///< kPreetham: default the sun's turbidity
    float scale = 1.f;                ///< kPreetham: multiplies the model's radiance
    /// kPreetham: the albedo of the ground below the horizon, a Lambertian plane lit by the sun and
    /// the sky (none: the sky below the horizon is black).
    std::optional<SpectrumSpec> ground_albedo;
};

struct LightConfig {
    using Kind = LightKind;  ///< kDirectional, kPoint or kSpot
    Kind kind = Kind::kDirectional;
    Vec3f direction{0, 0, -1};  ///< directional and spot: the direction light travels
    Vec3f position{0, 0, 0};    ///< point and spot
    SpectrumSpec spectrum;  ///< irradiance (directional, W m^-2 nm^-1) or intensity (W sr^-1 nm^-1)
    float cone_deg = 30.f, falloff_start_deg = 25.f;  ///< spot
    std::string where;                                ///< "scene.toml:12" for messages
};

/// [medium]: a homogeneous participating medium (haze, dust) filling a box, or the model's bounds.
/// [medium] grid's value that names the grid stored in the bricks rather than a file.
inline constexpr const char* kStoredGrid = "store";

struct MediumConfig {
    /// box_min, box_max (model units, metres); none: the model's bounds.
    std::optional<Bounds3f> box;
    /// A density grid instead of a box: an OpenVDB file (relative paths from the config's
    /// directory), the float grid's name in it, and a factor on its values.
    std::filesystem::path grid;
    /// grid = "store" (kStoredGrid): the grid `nave preprocess` cut into the store's bricks, each
    /// brick's piece loaded and evicted with the brick.
    bool stored_grid = false;
    std::string grid_name = "density";
    float density_scale = 1.f;
    SpectrumSpec sigma_a = SpectrumSpec::Constant(0.f);  ///< absorption coefficient, m^-1
    SpectrumSpec sigma_s = SpectrumSpec::Constant(0.f);  ///< scattering coefficient, m^-1
    /// Instead of sigma_a and sigma_s: the extinction coefficient σt (m^-1) and the single-
    /// scattering albedo σs / σt.
    std::optional<std::pair<SpectrumSpec, SpectrumSpec>> extinction_albedo;
    float g = 0.f;  ///< Henyey-Greenstein asymmetry, (-1, 1): > 0 scatters forward
    /// What it emits (scene/media/medium_emission.h): a radiance (W m^-2 sr^-1 nm^-1) where its
    /// density is, times the grid `emission_grid` of the `grid` file if named; or Planck's
    /// radiance at the temperature the grid `temperature_grid` holds (kelvin, times
    /// `temperature_scale`); either times `emission_scale`.
    std::optional<SpectrumSpec> emission;
    std::string emission_grid, temperature_grid;
    float temperature_scale = 1.f, emission_scale = 1.f;
    bool emits() const { return emission || !temperature_grid.empty(); }
    std::string where;            ///< file:line of the table, for messages
    std::string name = "medium";  ///< the table's name, for messages ("materials.water.medium")
};

struct MaterialConfig {
    enum class Kind { kDiffuse, kConductor, kDielectric, kThinDielectric, kBlack };
    Kind kind = Kind::kDiffuse;
    SpectrumSpec reflectance = SpectrumSpec::Constant(0.5f);  ///< diffuse albedo
    /// `reflectance = "model"`: the albedo is the model material's own colour (MTL Kd, glTF
    /// baseColorFactor, a STEP or IFC colour), lifted from linear sRGB to a spectrum.
    bool reflectance_from_model = false;
    SpectrumSpec eta = SpectrumSpec::Constant(1.5f);  ///< dielectric index, conductor eta
    SpectrumSpec k = SpectrumSpec::Constant(0.f);     ///< conductor absorption
    SpectrumSpec transmittance =
        SpectrumSpec::Constant(1.f);  ///< internal transmittance of thin glass per pass
    std::optional<SpectrumSpec> total_transmittance;  ///< measured total transmittance of a pane
    /// Glass (dielectric, thin_dielectric): the extinction coefficient k of the complex index
    /// n + ik, given as `k` or as the ellipsometric κ of ñ = n(1 + iκ) (`kappa`, k = nκ); with a
    /// pane's `thickness_mm` it sets the internal transmittance exp(-4π k d / λ) per pass, in solid
    /// glass the absorption coefficient 4π k / λ.
    std::optional<SpectrumSpec> glass_k;
    bool glass_k_is_kappa = false;
    float thickness_mm = 0.f;
    std::string builtin;  ///< a named material of the physics library (BuiltinMaterial)
    float roughness = 0.f;
    std::optional<SpectrumSpec> emission;  ///< radiance emitted by the surface
    bool portal = false;  ///< with render.photon_target = "portals", sun photons aim at it
    /// Use the model's textures for this material (albedo of a diffuse material, alpha cut-outs,
    /// emission).
    bool textures = true;
    /// Multiplies the radiance lifted from the model's emission texture (map_Ke, emissiveTexture):
    /// an RGB texel of luminance 1 emits a spectrum of luminance `emission_scale` (W m^-2 sr^-1
    /// nm^-1 units).
    float emission_scale = 1.f;
    /// [materials.NAME.medium]: the homogeneous medium filling a solid dielectric's inside (water,
    /// milky or tinted glass): coefficients and g as [medium]'s, no box or grid.
    std::optional<MediumConfig> medium;
    std::string where;
};

struct RenderSettings {
    enum class Mode { kPath, kPhoton };
    Mode mode = Mode::kPath;
    int spp = 16;  ///< path mode: samples per pixel; photon mode: camera samples per iteration
    double time_limit_s = 0;  ///< 0: none
    /// 0: none. Otherwise passes (path mode) or iterations (photon mode) stop once the render's own
    /// estimate of its relative mean squared error (docs/render.md, "Noise") is at most this; spp
    /// and iterations are then the most it does.
    double noise_target = 0;
    int iterations = 16;  ///< photon mode
    uint64_t photons_per_iteration = 200000;
    float initial_radius_m = 0.f;  ///< 0: chosen from the model size
    float alpha = 2.f / 3.f;       ///< photon mode radius reduction (Knaus & Zwicker 2011 eq. 16)
    int max_depth = 8;
    uint64_t seed = 1;
    int threads = 0;                 ///< 0: all cores
    uint32_t wave_paths = 1u << 20;  ///< camera paths in flight at once
    /// Whether the config or the command line set wave_paths; if not, `nave render --memory` may
    /// choose it (WavePathsUnderPaging, pager.h).
    bool wave_paths_chosen = false;
    /// Where photons from the sun and directional lights are aimed: the model's bounds projected
    /// onto the light's direction, or the triangles of materials marked `portal` (windows) only.
    enum class PhotonTarget { kBounds, kPortals };
    PhotonTarget photon_target = PhotonTarget::kBounds;
    /// How next-event estimation picks sky directions: uniformly over the sphere, or mostly toward
    /// the triangles of `portal` materials (windows), which an interior sees the sky through.
    enum class SkySampling { kUniform, kPortals };
    SkySampling sky_sampling = SkySampling::kUniform;
    /// Photon mode: where the sky's direct light at the visible points comes from: next-event
    /// estimation ("sampled", as sky_sampling says), or the sky's photons, deposited from their
    /// first hit on ("photons": smooth where a few windows among many let the sky in, which
    /// next-event estimation finds by chance; blurred over the gather radius like all photon
    /// light).
    enum class SkyDirect { kSampled, kPhotons };
    SkyDirect sky_direct = SkyDirect::kSampled;
    /// Photon mode: camera paths go one diffuse bounce past their first diffuse vertex (direct
    /// light there next-event estimated, with MIS) and read the photons where that bounce lands
    /// (final gathering, Jensen 1996), so no single photon is seen directly. Excludes sky_direct =
    /// "photons".
    bool final_gather = false;
    /// Photon mode aiming both the sky's samples and its photons at the portals: the sky's
    /// photons then teach its next-event estimation which windows light each region.
    bool LearnsSkyWindows() const {
        return mode == Mode::kPhoton && sky_sampling == SkySampling::kPortals &&
               photon_target == PhotonTarget::kPortals;
    }
    /// Path mode: paths learn where the light reflected toward each part of the model comes from
    /// and draw half of their continuations from it (PathGuide).
    bool path_guiding = false;
    /// Levels of detail (docs/render.md, "Levels of detail"): "auto" (the default) traces each
    /// ray against the coarsest level of each brick its footprint allows, where the store has
    /// levels (their image is within the noise of full detail's: "Paths through panes"); "full"
    /// traces full detail everywhere.
    enum class Lod { kAuto, kFull };
    Lod lod = Lod::kAuto;
};

struct OutputConfig {
    /// "none" (E), "D65", "D50", a colour temperature "5000K", or "scene": the light of the scene's
    /// sun and sky on a horizontal white surface (scene_white).
    std::string white_balance = "none";
    /// The chromatic adaptation transform of the white balance.
    AdaptationMethod adaptation = AdaptationMethod::kBradford;
    /// With white_balance "scene": the chromaticity of the scene's light (BuildRenderScene fills it
    /// in RenderScene::output).
    std::optional<Chromaticity> scene_white;
    float exposure_ev = 0.f;  ///< PNG only; EXR stays linear
    /// PNG exposure: kAuto maps the log-average luminance to middle grey; kPhysical exposes like a
    /// camera at `ev100` (metered from the log-average luminance in cd/m² when not given).
    enum class Exposure { kAuto, kPhysical };
    Exposure exposure = Exposure::kAuto;
    std::optional<double> ev100;
    /// PNG tone curve: kClip clips each channel at 1; kHuePreserving compresses the largest channel
    /// and scales the others with it, so saturated colours keep their hue and saturation.
    enum class Tone { kClip, kHuePreserving };
    Tone tone = Tone::kClip;
    bool aov_albedo = false, aov_normal = false, aov_depth = false;
};

/// The model's image textures (docs/textures.md).
struct TextureConfig {
    bool enabled = true;  ///< false: every material keeps its flat config colour
    uint64_t cache_bytes = uint64_t(256)
                           << 20;  ///< tile cache cap when `nave render` has no --memory
    double memory_share = 0.2;     ///< with --memory: the cache's share of the budget
};

struct SceneConfig {
    std::filesystem::path path;
    CameraConfig camera;
    SunConfig sun;
    SkyConfig sky;
    std::vector<LightConfig> lights;
    std::optional<MediumConfig> medium;
    std::map<std::string, MaterialConfig> materials;  ///< by model material name or glob pattern
                                                      ///< ("*glazing*"); "default" for the rest
    RenderSettings render;
    OutputConfig output;
    TextureConfig textures;
};

/// Parses and checks a scene config file. Errors name the file, line and column, and the key.
StatusOr<SceneConfig> LoadSceneConfig(const std::filesystem::path& path);
/// Same from text (`name` is used in messages).
StatusOr<SceneConfig> ParseSceneConfig(std::string_view text, const std::string& name);

/// Parses "2025-06-21T08:00+02:00" (seconds optional, "Z" for UTC). Errors say which field is
/// wrong.
StatusOr<DateTime> ParseDateTime(std::string_view text);

}  // namespace nave::render
