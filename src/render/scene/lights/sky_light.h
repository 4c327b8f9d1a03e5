#pragma once
// The sky: radiance from every direction, uniform or the Preetham model (render/scene/sun/sky.h)
// with the ground below the horizon. Its next-event estimation mixes uniform directions with
// directions toward the windows, and its photons likewise (LightSampler::SampleSky,
// PhotonEmitters): the portals are transport's; the radiance, the uniform sampling and the power
// are the sky's.

#include <memory>
#include <vector>

#include "src/core/sampling.h"
#include "src/render/scene/lights/light.h"
#include "src/render/scene/sun/sky.h"

namespace nave::render {

class SkyLight final : public Light {
  public:
    /// A uniform sky of `radiance` (W m^-2 sr^-1 nm^-1) in every direction, above and below.
    explicit SkyLight(Spectrum radiance) : Light(LightKind::kSky), radiance_(radiance) {}
    /// A physical sky, its radiance times `scale`; black below the horizon until
    /// set_ground_radiance.
    SkyLight(std::shared_ptr<const PreethamSky> preetham, float scale)
        : Light(LightKind::kSky), preetham_(std::move(preetham)), scale_(scale) {}

    /// Radiance of the sky seen in direction `w` (world), at the path's wavelengths: below the
    /// horizon of a physical sky, the ground's.
    SampledSpectrum Radiance(const Vec3f& w, const SampledWavelengths& lambda) const {
        if (preetham_) {
            return w.z > 0 ? preetham_->Radiance(w, lambda) * scale_
                           : ground_radiance_.Sample(lambda);
        }
        return radiance_.Sample(lambda);
    }
    /// The same as a full spectrum (for tools and the power).
    Spectrum RadianceSpectrum(const Vec3f& w) const {
        if (preetham_) return w.z > 0 ? preetham_->RadianceSpectrum(w) * scale_ : ground_radiance_;
        return radiance_;
    }
    /// A direction uniform on the sphere, and its solid-angle pdf.
    static Vec3f SampleUniform(Point2f u) { return SampleUniformSphere(u); }
    static constexpr float UniformPdf() { return UniformSpherePdf(); }
    /// Adds to `e` (Spectrum::kNumSamples entries, W m⁻² nm⁻¹) the sky's irradiance above the
    /// horizon on a horizontal surface facing up, ∫ L cos θ dω over the upper hemisphere: π L for a
    /// uniform sky, a 64 x 128 midpoint quadrature in cos θ and φ for a physical one.
    void AddHorizontalIrradiance(std::vector<double>* e) const;
    /// The largest of the sky's radiances along the six axis directions, averaged over the
    /// wavelengths SampledWavelengths::SampleVisible(0.5) draws: the order of the light the sky
    /// brings, for scales of learned sums.
    double BrightestAxisRadiance() const;
    /// With a physical sky: the radiance of the ground below the horizon.
    void set_ground_radiance(Spectrum radiance) { ground_radiance_ = radiance; }
    /// The mean radiance over the sphere of directions times the measure of the lines its photons
    /// cross (target.line_measure).
    double Power(const PhotonTarget& target) const override;

  private:
    Spectrum radiance_;                            // uniform sky
    std::shared_ptr<const PreethamSky> preetham_;  // physical sky, or null
    float scale_ = 1;
    // With a physical sky and [sky] ground_albedo: the radiance of the ground below the horizon
    // (albedo / π times HorizontalIrradiance); otherwise zero there.
    Spectrum ground_radiance_;
};

}  // namespace nave::render
