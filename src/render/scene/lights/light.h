#pragma once
// Lights as objects: one class per kind, each in a file of its own beside this one, all behind the
// interface below. The conventions, once for all of them:
//
// - Units: spectra are per nanometre of wavelength. Radiance W m^-2 sr^-1 nm^-1 (sun, sky, emissive
//   triangles), irradiance at normal incidence W m^-2 nm^-1 (directional), intensity W sr^-1 nm^-1
//   (point, spot). Lengths in metres.
// - Directions are unit vectors in the world frame (+X east, +Y north, +Z up). `wi` and `to_light`
//   point from the scene toward the light; a photon's `dir` is the way it travels.
// - Next-event estimation (Light::SampleLi) measures its pdf per unit solid angle at the shading
//   point; a delta light (one direction from each point: directional, point, spot) has pdf 0, no
//   BSDF-sampled ray can find it, and it is never weighted by MIS.
// - A photon's power is what it carries divided by the densities it was drawn with (W nm^-1):
//   PhotonEmitters divides it further by the probability of choosing its light.
// - Power is a rough weight for choosing among emitters: the light's emitted power (W nm^-1; for a
//   light far away, what crosses where its photons start) averaged over 400-700 nm (MeanVisible).
//   Any positive weight keeps photon mapping unbiased; a good one only lowers noise.
//
// A new kind of light is one new file here and one line in the factory (MakeLight, scene.cpp);
// one that photons leave from a place implements SamplePhoton, one far away derives from
// DistantLight.

#include <limits>
#include <optional>

#include "src/core/sampling.h"
#include "src/core/spectrum.h"
#include "src/core/vecmath.h"

namespace nave::render {

/// The kinds of light, for the config ([[lights]] type: directional, point, spot; the sun and the
/// sky have tables of their own) and for the renderer.
enum class LightKind { kSun, kDirectional, kPoint, kSpot, kSky, kTriangle };

/// A rough power of a spectrum for choosing emitters: its mean over 400-700 nm.
float MeanVisible(const Spectrum& s);

/// What next-event estimation draws toward a light from a shading point.
struct LightSample {
    Vec3f wi;  ///< unit direction from the point toward the light
    /// The light's factor of the estimate, to multiply by f |cos θ|: radiance / pdf for a light
    /// sampled in solid angle; irradiance at normal incidence (directional) or intensity / d²
    /// (point, spot) for a delta light.
    SampledSpectrum weight;
    float pdf = 0;  ///< solid angle (sr^-1); 0 for a delta light
    /// Length of the shadow ray: short of a light at a place.
    float t_max = std::numeric_limits<float>::infinity();
};

/// A photon leaving a light at a place (point, spot, emissive triangle).
struct PhotonSample {
    Vec3f origin, dir;  ///< where it starts and the way it travels (unit)
    /// W nm^-1, divided by the densities of origin and direction.
    SampledSpectrum power;
};

/// The random numbers a photon of a light at a place is drawn with, each in [0, 1).
struct PhotonRandoms {
    Point2f u_position;  ///< where on the light
    Point2f u_direction;
    float u_side = 0;  ///< which side of a two-sided emitter
};

/// Where the photons of lights far away start, for their power (PhotonEmitters): the area facing
/// the light they cross (m², a disc covering the model or the windows' projection) and, for the
/// sky, the measure of the lines they cross (dA⊥ dω, m² sr).
struct PhotonTarget {
    double area = 0;
    double line_measure = 0;
};

class DistantLight;

/// A light of the scene. Immutable once built: thread-safe.
class Light {
  public:
    explicit Light(LightKind kind) : kind_(kind) {}
    virtual ~Light() = default;

    LightKind kind() const { return kind_; }

    /// Next-event estimation from point `p` with random numbers `u`, at wavelengths `lambda`;
    /// nothing when the light sends nothing to `p`. Lights that next-event estimation does not
    /// sample this way return nothing: the sky (LightSampler::SampleSky, which aims at the
    /// windows) and emissive triangles (paths find them).
    virtual std::optional<LightSample> SampleLi(const Vec3f& p, Point2f u,
                                                const SampledWavelengths& lambda) const {
        return std::nullopt;
    }
    /// A photon of a light at a place. Lights far away (DistantLight, the sky) start their photons
    /// where PhotonEmitters says and do not implement it.
    virtual PhotonSample SamplePhoton(const PhotonRandoms& u,
                                      const SampledWavelengths& lambda) const;
    /// The rough power of the light (see the conventions above) whose photons cross `target`.
    virtual double Power(const PhotonTarget& target) const = 0;
    /// This light as a light far away whose photons start on a plane facing it, or null.
    virtual const DistantLight* distant() const { return nullptr; }
    /// The angle (radians) the light spans seen from the scene, 0 for a point or a direction. A
    /// shadow ray toward it is one sample of that cone, and its shadows' penumbrae are as wide:
    /// an occluder at distance d blurs over d times this angle, so geometry coarser by less than
    /// that cannot show in them (the ray's footprint, level_choice.h).
    virtual float ShadowSpread() const { return 0.f; }

  private:
    LightKind kind_;
};

/// A light far away in one direction (sun, directional): its photons start on a plane facing it
/// (PhotonEmitters::StartDistantPhoton: a disc covering the model, the windows, the photon guide),
/// in two steps: the direction first, then the power once the start point's density is known.
class DistantLight : public Light {
  public:
    DistantLight(LightKind kind, const Vec3f& to_light) : Light(kind), to_light_(to_light) {}
    /// Unit direction toward the light (the centre of the sun's disc).
    const Vec3f& to_light() const { return to_light_; }
    /// A photon's direction toward the light (it travels the opposite way).
    virtual Vec3f SamplePhotonDirection(Point2f u) const = 0;
    /// The power of a photon toward `to` (SamplePhotonDirection) whose start point was drawn with
    /// area density 1 / `area` (m²) on the plane facing the light.
    virtual SampledSpectrum PhotonPower(const Vec3f& to, float area,
                                        const SampledWavelengths& lambda) const = 0;
    const DistantLight* distant() const override { return this; }

  private:
    Vec3f to_light_;
};

}  // namespace nave::render
