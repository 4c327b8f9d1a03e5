#include "src/render/scene/scene.h"

#include <fmt/ostream.h>
#include <fnmatch.h>

#include <cmath>
#include <map>
#include <numbers>
#include <variant>

#include "src/core/log.h"
#include "src/core/rgb_to_spectrum.h"
#include "src/render/bricks/vdb_density.h"
#include "src/render/scene/lights/directional_light.h"
#include "src/render/scene/lights/point_light.h"
#include "src/render/scene/lights/spot_light.h"
#include "src/render/scene/materials/ior.h"
#include "src/render/scene/sun/sun.h"

namespace nave::render {

Spectrum ToSpectrum(const SpectrumSpec& spec) {
    if (spec.kind == SpectrumSpec::Kind::kConstant)
        return Spectrum::Constant(spec.value * spec.scale);
    return Spectrum::FromFunction(
        [&](double lambda_nm) { return spec.Evaluate(float(lambda_nm)); });
}

float SurfaceMaterial::AlbedoForAov() const {
    if (black) return 0;
    if (const auto* d = std::get_if<DiffuseMaterial>(&material)) return d->albedo.Evaluate(550);
    return 1;
}

bool SurfaceMaterial::MakesCaustics() const {
    if (black) return false;
    if (const auto* d = std::get_if<DielectricMaterial>(&material))
        return TrowbridgeReitz(d->alpha, d->alpha).EffectivelySmooth();
    if (const auto* c = std::get_if<ConductorMaterial>(&material))
        return TrowbridgeReitz(c->alpha_x, c->alpha_y).EffectivelySmooth();
    return false;
}

Spectrum HorizontalIrradiance(const RenderScene& scene) {
    std::vector<double> e(Spectrum::kNumSamples, 0.0);
    if (scene.sky) scene.sky->AddHorizontalIrradiance(&e);
    if (scene.sun >= 0) {
        const SunLight& sun = scene.sun_light();
        const double sun_e = sun.SolidAngle() * std::max(0.0, double(sun.to_light().z));
        for (int k = 0; k < Spectrum::kNumSamples; ++k)
            e[size_t(k)] += sun_e * sun.radiance().sample(k);
    }
    return Spectrum::FromFunction(
        [&](double lambda) { return e[size_t(int(lambda - kLambdaMinNm))]; });
}

std::unique_ptr<Light> MakeLight(const LightConfig& config) {
    switch (config.kind) {
        case LightKind::kDirectional:
            return std::make_unique<DirectionalLight>(config.direction,
                                                      ToSpectrum(config.spectrum));
        case LightKind::kPoint:
            return std::make_unique<PointLight>(config.position, ToSpectrum(config.spectrum));
        case LightKind::kSpot:
            return std::make_unique<SpotLight>(
                config.position, config.direction, std::cos(config.cone_deg * kPi / 180.f),
                std::cos(config.falloff_start_deg * kPi / 180.f), ToSpectrum(config.spectrum));
        case LightKind::kSun:
        case LightKind::kSky:
        case LightKind::kTriangle:
            break;  // the sun and the sky have tables of their own; triangles come from the model
    }
    NAVE_CHECK(false) << "[[lights]] has no light of kind " << int(config.kind);
    return nullptr;
}

namespace {

/// The extinction coefficient k of a glass config: `k` as given, or `kappa` times n (ñ = n(1 +
/// iκ)).
Spectrum GlassK(const MaterialConfig& mc) {
    const Spectrum k = ToSpectrum(*mc.glass_k);
    return mc.glass_k_is_kappa ? k * ToSpectrum(mc.eta) : k;
}

/// The physics material a config table describes.
StatusOr<Material> ToMaterial(const MaterialConfig& mc, const std::string& name) {
    if (!mc.builtin.empty()) {
        StatusOr<Material> m = BuiltinMaterial(mc.builtin);
        if (!m.ok())
            return m.status().WithContext(fmt::format("{}: materials.{}.builtin", mc.where, name));
        return m;
    }
    switch (mc.kind) {
        case MaterialConfig::Kind::kDiffuse:
            return Material(DiffuseMaterial{ToSpectrum(mc.reflectance)});
        case MaterialConfig::Kind::kConductor: {
            float a = RoughnessToAlpha(mc.roughness);
            return Material(ConductorMaterial{ToSpectrum(mc.eta), ToSpectrum(mc.k), a, a});
        }
        case MaterialConfig::Kind::kDielectric: {
            DielectricMaterial d;
            d.eta = ToSpectrum(mc.eta);
            d.alpha = RoughnessToAlpha(mc.roughness);
            if (mc.glass_k) d.absorption_per_m = AbsorptionPerMetre(GlassK(mc));
            return Material(d);
        }
        case MaterialConfig::Kind::kThinDielectric:
            if (mc.glass_k) {
                // Internal transmittance of one pass at normal incidence: exp(-α d), α = 4πk/λ.
                return Material(ThinGlassMaterial::FromAbsorption(ToSpectrum(mc.eta),
                                                                  AbsorptionPerMetre(GlassK(mc)),
                                                                  double(mc.thickness_mm) * 1e-3));
            }
            if (mc.total_transmittance) {
                return Material(ThinGlassMaterial::FromTotalTransmittance(
                    ToSpectrum(mc.eta), ToSpectrum(*mc.total_transmittance)));
            }
            return Material(ThinGlassMaterial{ToSpectrum(mc.eta), ToSpectrum(mc.transmittance)});
        case MaterialConfig::Kind::kBlack:
            break;
    }
    return Material(DiffuseMaterial{Spectrum::Constant(0.f)});
}

}  // namespace

StatusOr<SunState> ResolveSun(const SunConfig& sun, const std::string& file) {
    SunState s;
    if (sun.direction) {
        s.to_sun = *sun.direction;
        s.angular_radius_rad = double(sun.angular_radius_deg) * std::numbers::pi / 180;
        s.zenith_deg = std::acos(std::clamp(s.to_sun.z, -1.f, 1.f)) * 180.0 / std::numbers::pi;
        s.azimuth_deg =
            std::fmod(std::atan2(s.to_sun.x, s.to_sun.y) * 180.0 / std::numbers::pi + 360.0, 360.0);
        if (sun.radiance) {
            s.radiance = ToSpectrum(*sun.radiance);
        } else {
            // A fixed direction without a spectrum: the clear-sky spectrum of the physics model for
            // that zenith angle would need a date; use the extraterrestrial spectrum (ASTM E-490)
            // spread over the disc, i.e. the sun without an atmosphere.
            const double omega = ConeSolidAngle(s.angular_radius_rad);
            s.radiance = ExtraterrestrialSolarSpectrum() * float(1.0 / omega);
        }
    } else {
        SunInput in;
        in.time = CivilTime{sun.when.year,
                            sun.when.month,
                            sun.when.day,
                            sun.when.hour,
                            sun.when.minute,
                            sun.when.second,
                            sun.when.utc_offset_minutes / 60.0};
        in.latitude_deg = sun.latitude_deg;
        in.longitude_deg = sun.longitude_deg;
        in.elevation_m = sun.elevation_m;
        in.atmosphere.pressure_hpa = sun.pressure_mbar;  // 1 mbar = 1 hPa
        in.atmosphere.temperature_c = sun.temperature_c;
        in.atmosphere.turbidity = sun.turbidity;
        StatusOr<Sun> model = ComputeSun(in);
        if (!model.ok()) return model.status().WithContext(fmt::format("{}: [sun]", file));
        s.to_sun = model->direction;
        s.zenith_deg = model->position.zenith_deg;
        s.azimuth_deg = model->position.azimuth_deg;
        s.angular_radius_rad = model->angular_radius_rad;
        s.radiance = sun.radiance ? ToSpectrum(*sun.radiance) : model->radiance;
        s.above_horizon = model->AboveHorizon();
    }
    s.radiance *= sun.scale;
    return s;
}

namespace {

/// True for a [materials] key that is a glob pattern ("*glazing*", "IfcWall:*"), not a name.
bool IsPattern(const std::string& key) { return key.find_first_of("*?[") != std::string::npos; }

/// True when the [materials] key `key` (a name or a pattern) maps the model material `name`.
bool KeyMaps(const std::string& key, const std::string& name) {
    return IsPattern(key) ? fnmatch(key.c_str(), name.c_str(), 0) == 0 : key == name;
}

/// The config mapping of a model material: its own table, else the longest pattern that matches
/// it (the most specific; ties go to the first in key order), else "default", else null.
const std::pair<const std::string, MaterialConfig>* FindMapping(const SceneConfig& config,
                                                                const std::string& name) {
    auto it = config.materials.find(name);
    if (it != config.materials.end()) return &*it;
    const std::pair<const std::string, MaterialConfig>* best = nullptr;
    for (const auto& entry : config.materials) {
        if (!IsPattern(entry.first) || !KeyMaps(entry.first, name)) continue;
        if (best == nullptr || entry.first.size() > best->first.size()) best = &entry;
    }
    if (best != nullptr) return best;
    it = config.materials.find("default");
    return it == config.materials.end() ? nullptr : &*it;
}

}  // namespace

Status AttachTextures(const SceneConfig& config, const std::filesystem::path& base_dir,
                      TextureCache& cache, RenderScene* scene, std::vector<std::string>* warnings) {
    if (!config.textures.enabled) return Status::Ok();
    const auto& records = scene->source->materials();
    NAVE_CHECK_EQ(records.size(), scene->materials.size());
    AlphaMasks masks(records.size());
    bool any_mask = false;
    for (size_t i = 0; i < records.size(); ++i) {
        const store::MaterialRecord& rec = records[i];
        if (rec.textures.empty()) continue;
        const auto* mapping = FindMapping(config, rec.name);
        NAVE_CHECK(mapping != nullptr);  // BuildRenderScene refused unmapped materials
        const MaterialConfig& mc = mapping->second;
        if (!mc.textures) continue;
        SurfaceMaterial& m = scene->materials[i];
        SurfaceTextureOptions options;
        options.use_albedo = std::holds_alternative<DiffuseMaterial>(m.material);
        options.use_transmittance = std::holds_alternative<ThinGlassMaterial>(m.material);
        options.use_emission =
            !mc.emission;  // the config's emission overrides the model's, texture included
        options.emission_scale = mc.emission_scale;
        std::shared_ptr<const SurfaceTextures> t =
            OpenSurfaceTextures(cache, rec, base_dir, options, warnings);
        if (t == nullptr) continue;
        if (t->emission) m.emissive = true;
        if (t->alpha) {
            masks[i] = t;
            any_mask = true;
        }
        m.textures = std::move(t);
    }
    if (any_mask) scene->source->SetAlphaMasks(std::move(masks));
    return Status::Ok();
}

namespace {

/// What the medium of `config` emits (null: nothing). Errors: a negative emission, photon mode
/// (photons are not emitted from media), a grid the plugin cannot read (naming the table and key).
StatusOr<std::shared_ptr<const MediumEmission>> MakeMediumEmission(const MediumConfig& config,
                                                                   const RenderScene& scene) {
    if (!config.emits()) return std::shared_ptr<const MediumEmission>();
    if (scene.settings.mode == RenderSettings::Mode::kPhoton)
        return InvalidArgumentError(
            "{}: [{}] emits light ({}): photon mode emits no photons from media, so the light "
            "would be missing: render it with render.mode = \"path\"",
            config.where, config.name, config.emission ? "emission" : "temperature_grid");
    const auto read_grid =
        [&](const char* key,
            const std::string& name) -> StatusOr<std::shared_ptr<const volumes::ScalarGrid>> {
        NAVE_ASSIGN_OR_RETURN(const volumes::VdbPlugin* plugin, volumes::LoadVdbPlugin());
        StatusOr<std::unique_ptr<volumes::ScalarGrid>> grid =
            plugin->ReadScalarGrid(config.grid, name);
        if (!grid.ok())
            return Status(grid.status().code(),
                          fmt::format("{}: [{}] {}: {}", config.where, config.name, key,
                                      grid.status().message()));
        return std::shared_ptr<const volumes::ScalarGrid>(std::move(*grid));
    };
    if (!config.temperature_grid.empty()) {
        NAVE_ASSIGN_OR_RETURN(std::shared_ptr<const volumes::ScalarGrid> kelvin,
                              read_grid("temperature_grid", config.temperature_grid));
        return std::make_shared<const MediumEmission>(MediumEmission::Blackbody(
            std::move(kelvin), config.temperature_scale, config.emission_scale));
    }
    const Spectrum le = ToSpectrum(*config.emission) * config.emission_scale;
    for (float nm = kLambdaMinNm; nm <= kLambdaMaxNm; nm += 1)
        if (!(le.Evaluate(nm) >= 0))
            return InvalidArgumentError(
                "{}: {}.emission is {} at {} nm: a radiance cannot be negative", config.where,
                config.name, le.Evaluate(nm), nm);
    if (config.emission_grid.empty())
        return std::make_shared<const MediumEmission>(MediumEmission::Uniform(le));
    NAVE_ASSIGN_OR_RETURN(std::shared_ptr<const volumes::ScalarGrid> scale,
                          read_grid("emission_grid", config.emission_grid));
    return std::make_shared<const MediumEmission>(MediumEmission::Scaled(le, std::move(scale)));
}

/// The medium of [medium] or of a material's medium table (the model's bounds when it gives no
/// box: a solid's inside lies within them). Errors: negative coefficients, a medium beyond the
/// model's box in photon mode, an empty model without a box.
StatusOr<std::shared_ptr<const Medium>> MakeMedium(const MediumConfig& config,
                                                   const RenderScene& scene) {
    Spectrum sigma_a = ToSpectrum(config.sigma_a), sigma_s = ToSpectrum(config.sigma_s);
    if (config.extinction_albedo) {
        const Spectrum sigma_t = ToSpectrum(config.extinction_albedo->first);
        const Spectrum albedo = ToSpectrum(config.extinction_albedo->second);
        for (float nm = kLambdaMinNm; nm <= kLambdaMaxNm; nm += 1)
            if (!(albedo.Evaluate(nm) >= 0 && albedo.Evaluate(nm) <= 1))
                return InvalidArgumentError(
                    "{}: {}.albedo is {} at {} nm: a fraction of the extinction, in [0, 1]",
                    config.where, config.name, albedo.Evaluate(nm), nm);
        // σs = α σt and σa = (1 - α) σt (the single-scattering albedo's definition).
        sigma_s = Spectrum::FromFunction(
            [&](double nm) { return sigma_t.Evaluate(float(nm)) * albedo.Evaluate(float(nm)); });
        sigma_a = Spectrum::FromFunction([&](double nm) {
            return sigma_t.Evaluate(float(nm)) * (1 - albedo.Evaluate(float(nm)));
        });
    }
    for (float nm = kLambdaMinNm; nm <= kLambdaMaxNm; nm += 1) {
        for (const auto& [key, spectrum] : {std::pair{"sigma_a", &sigma_a}, {"sigma_s", &sigma_s}})
            if (!(spectrum->Evaluate(nm) >= 0))
                return InvalidArgumentError(
                    "{}: {}.{} is {} at {} nm: a coefficient (m^-1) cannot be negative",
                    config.where, config.name, key, spectrum->Evaluate(nm), nm);
    }
    std::shared_ptr<const DensityField> density;
    if (config.stored_grid) {
        // The density comes brick by brick with the bricks (Medium::DensityIn).
        if (Status s = scene.source->UseStoredMedium(config.density_scale); !s.ok())
            return Status(s.code(), fmt::format("{}: [medium] grid = \"{}\": {}", config.where,
                                                kStoredGrid, s.message()));
    } else if (!config.grid.empty()) {
        StatusOr<std::shared_ptr<const VdbDensity>> grid =
            VdbDensity::Load(config.grid, config.grid_name, config.density_scale);
        if (!grid.ok())
            return Status(grid.status().code(), fmt::format("{}: [medium] grid: {}", config.where,
                                                            grid.status().message()));
        density = *grid;
    } else {
        const Bounds3f box = config.box.value_or(scene.source->bounds());
        if (box.Empty())
            return InvalidArgumentError("{}: [{}] has no box_min/box_max and the model is empty",
                                        config.where, config.name);
        density = std::make_shared<BoxDensity>(box);
    }
    if (density && scene.settings.mode == RenderSettings::Mode::kPhoton) {
        // Photons fly only from the first brick they enter (they start far outside the model):
        // a medium beyond the model's box would dim them by how far away they were started.
        const Bounds3f model = scene.source->bounds(), b = density->bounds();
        const float slack = 1e-4f * Length(model.Diagonal());
        for (int a = 0; a < 3; ++a)
            if (b.min[a] < model.min[a] - slack || b.max[a] > model.max[a] + slack)
                return InvalidArgumentError(
                    "{}: [medium] spans {}, beyond the model's box {}: photon mode needs the "
                    "medium "
                    "inside it (give box_min/box_max inside it, or render.mode = \"path\")",
                    config.where, fmt::streamed(b), fmt::streamed(model));
    }
    NAVE_ASSIGN_OR_RETURN(std::shared_ptr<const MediumEmission> emission,
                          MakeMediumEmission(config, scene));
    return std::shared_ptr<const Medium>(
        std::make_shared<const Medium>(density, sigma_a, sigma_s, config.g, std::move(emission)));
}

/// Gives `m`, made from config table `mc` (named `name`), its inside: a solid dielectric's is
/// kClearSolid or the medium of its table (one per table, made once, `made` remembering which).
/// Errors: a medium table on a material with no inside, more media than a ray's byte can name.
Status GiveInside(const MaterialConfig& mc, const std::string& name, RenderScene* scene,
                  std::map<std::string, uint8_t>* made, SurfaceMaterial* m) {
    const bool solid = !m->black && std::holds_alternative<DielectricMaterial>(m->material);
    if (!solid) {
        if (mc.medium)
            return InvalidArgumentError(
                "{}: {}: only a solid dielectric has an inside to fill; materials.{} is not one",
                mc.medium->where, mc.medium->name, name);
        return Status::Ok();
    }
    m->medium_inside = kClearSolid;
    if (!mc.medium) return Status::Ok();
    if (auto it = made->find(name); it != made->end()) {
        m->medium_inside = it->second;
        return Status::Ok();
    }
    if (scene->inside_media.size() + kClearSolid > 255)
        return InvalidArgumentError(
            "{}: {}: more than {} materials with a medium inside (a ray names its medium in a "
            "byte)",
            mc.medium->where, mc.medium->name, 255 - kClearSolid);
    NAVE_ASSIGN_OR_RETURN(std::shared_ptr<const Medium> medium, MakeMedium(*mc.medium, *scene));
    m->medium_inside = uint8_t(scene->inside_media.size() + kClearSolid);
    scene->inside_media.push_back(std::move(medium));
    made->emplace(name, m->medium_inside);
    return Status::Ok();
}

}  // namespace

StatusOr<RenderScene> BuildRenderScene(const SceneConfig& config, BrickSource& source) {
    // First, before anything loads a brick: the levels in use decide the slots the pager sees.
    NAVE_RETURN_IF_ERROR(
        source.UseLevels(config.render.lod == RenderSettings::Lod::kFull ? 1 : ~uint32_t(0)));
    RenderScene scene;
    scene.source = &source;
    scene.camera = std::make_unique<Camera>(config.camera);
    scene.settings = config.render;
    scene.output = config.output;
    const std::string file = config.path.string();

    // Materials: every model material needs a mapping (or the default).
    scene.inside_media = {nullptr};  // kClearSolid
    std::map<std::string, uint8_t> inside_made;
    const auto& records = source.materials();
    for (size_t i = 0; i < records.size(); ++i) {
        const store::MaterialRecord& rec = records[i];
        const auto* it = FindMapping(config, rec.name);
        if (it == nullptr) {
            return InvalidArgumentError(
                "{}: the model's material '{}' has no mapping: add [materials.{}] or "
                "[materials.default]",
                file, rec.name, rec.name);
        }
        const MaterialConfig& mc = it->second;
        SurfaceMaterial m;
        m.name = rec.name;
        NAVE_ASSIGN_OR_RETURN(m.material, ToMaterial(mc, it->first));
        if (mc.builtin.empty() && mc.reflectance_from_model) {
            // The model's own colour, linear sRGB, lifted to a reflectance spectrum
            // (core/rgb_to_spectrum.h: Jakob & Hanika 2019).
            const SigmoidPolynomial albedo =
                UpliftReflectance(Vec3f(rec.diffuse[0], rec.diffuse[1], rec.diffuse[2]));
            m.material = DiffuseMaterial{
                Spectrum::FromFunction([&](double nm) { return albedo.Evaluate(float(nm)); })};
        }
        m.black = mc.builtin.empty() && mc.kind == MaterialConfig::Kind::kBlack;
        m.portal = mc.portal;
        if (mc.emission) {
            m.emissive = true;
            m.emission = ToSpectrum(*mc.emission);
        } else if (rec.emission[0] > 0 || rec.emission[1] > 0 || rec.emission[2] > 0) {
            // [texture] The model's own emission (MTL Ke, glTF emissiveFactor) is linear sRGB:
            // lifted to a spectrum with its chromaticity (core/rgb_to_spectrum.h, Jakob & Hanika
            // 2019 times the D65 white), whose luminance is the Rec. 709 luma of the RGB; a config
            // emission overrides it.
            m.emissive = true;
            m.emission =
                RgbEmission(Vec3f(rec.emission[0], rec.emission[1], rec.emission[2])).ToSpectrum();
        }
        NAVE_RETURN_IF_ERROR(GiveInside(mc, it->first, &scene, &inside_made, &m));
        scene.materials.push_back(std::move(m));
    }
    for (const auto& entry : config.materials) {
        // Not a structured binding: clang before 16 (the fuzz preset's) cannot capture one.
        const std::string& name = entry.first;
        if (name == "default") continue;
        bool used = std::any_of(records.begin(), records.end(),
                                [&](const auto& r) { return KeyMaps(name, r.name); });
        if (!used)
            log::Warning("{}: [materials.{}] maps no material of the model", entry.second.where,
                         name);
    }

    if (config.sun.enabled) {
        NAVE_ASSIGN_OR_RETURN(SunState sun, ResolveSun(config.sun, file));
        if (!sun.above_horizon)
            log::Warning("{}: the sun is below the horizon at that date and place", file);
        scene.sun = int(scene.lights.size());
        scene.lights.push_back(
            std::make_unique<SunLight>(sun.to_sun, sun.angular_radius_rad, sun.radiance));
        scene.sun_description = fmt::format("azimuth {:.2f} deg, elevation {:.2f} deg",
                                            sun.azimuth_deg, 90.0 - sun.zenith_deg);
    }
    for (const LightConfig& lc : config.lights) scene.lights.push_back(MakeLight(lc));
    if (config.medium) {
        NAVE_ASSIGN_OR_RETURN(scene.medium, MakeMedium(*config.medium, scene));
    }
    if (config.sky.kind == SkyConfig::Kind::kUniform) {
        scene.sky = std::make_unique<SkyLight>(ToSpectrum(config.sky.radiance));
    } else if (config.sky.kind == SkyConfig::Kind::kPreetham && scene.sun >= 0) {
        double turbidity =
            std::clamp(config.sky.turbidity.value_or(config.sun.turbidity), 1.7, 10.0);
        scene.sky = std::make_unique<SkyLight>(
            std::make_shared<PreethamSky>(scene.sun_light().to_light(), float(turbidity)),
            config.sky.scale);
        if (config.sky.ground_albedo) {
            // Lambertian: L = ρ E / π (the parser checked ρ is within [0, 1]).
            scene.sky->set_ground_radiance(ToSpectrum(*config.sky.ground_albedo) *
                                           HorizontalIrradiance(scene) *
                                           float(1 / std::numbers::pi));
        }
    }
    if (scene.output.white_balance == "scene") {
        const Vec3d white = SpectrumToXYZ(HorizontalIrradiance(scene));
        if (!(white.y > 0)) {
            return InvalidArgumentError(
                "{}: [output] white_balance = \"scene\" needs a sun above the horizon or a sky",
                file);
        }
        scene.output.scene_white = XYZToChromaticity(white);
    }
    return scene;
}

}  // namespace nave::render
