#pragma once
// The sun: a disc of uniform radiance (no limb darkening) of angular radius of a quarter degree or
// so, sampled in solid angle; its direction and spectrum come from the physics sun model or the
// config (ResolveSun, scene.h).

#include "src/core/sampling.h"
#include "src/render/scene/lights/light.h"
#include "src/render/scene/materials/frame.h"

namespace nave::render {

class SunLight final : public DistantLight {
  public:
    /// The sun toward unit direction `to_sun`, its disc of angular radius `radius_rad`, of
    /// `radiance` (W m^-2 sr^-1 nm^-1).
    SunLight(const Vec3f& to_sun, double radius_rad, Spectrum radiance)
        : DistantLight(LightKind::kSun, to_sun), radius_rad_(radius_rad), radiance_(radiance) {}

    const Spectrum& radiance() const { return radiance_; }
    /// The disc's solid angle (sr) and the pdf of Sample, in double where it matters (the disc
    /// spans 1 - cos θ ≈ 1.1e-5).
    double SolidAngle() const { return ConeSolidAngle(radius_rad_); }
    float Pdf() const { return float(1 / SolidAngle()); }
    /// A direction uniform over the disc.
    Vec3f Sample(Point2f u) const {
        return Normalize(
            Frame::FromZ(to_light()).FromLocal(SampleUniformNarrowCone(u, radius_rad_)));
    }
    /// Whether direction `w` (unit) is within the disc.
    bool Sees(const Vec3f& w) const { return InNarrowCone(w, to_light(), radius_rad_); }

    std::optional<LightSample> SampleLi(const Vec3f& p, Point2f u,
                                        const SampledWavelengths& lambda) const override;
    Vec3f SamplePhotonDirection(Point2f u) const override { return Sample(u); }
    SampledSpectrum PhotonPower(const Vec3f& to, float area,
                                const SampledWavelengths& lambda) const override;
    double Power(const PhotonTarget& target) const override;
    /// The disc's angular diameter (0.53 degrees from the Earth).
    float ShadowSpread() const override { return float(2 * radius_rad_); }

  private:
    double radius_rad_;
    Spectrum radiance_;
};

}  // namespace nave::render
