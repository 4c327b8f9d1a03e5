#include "src/render/scene/lights/sky_light.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace nave::render {

void SkyLight::AddHorizontalIrradiance(std::vector<double>* e) const {
    if (preetham_) {
        // ∫ L cos θ dω = ∫∫ L(μ, φ) μ dμ dφ over μ in (0, 1].
        constexpr int kMu = 64, kPhi = 128;
        const double cell = (1.0 / kMu) * (2 * std::numbers::pi / kPhi) * scale_;
        for (int i = 0; i < kMu; ++i) {
            const double mu = (i + 0.5) / kMu, r = std::sqrt(1 - mu * mu);
            for (int j = 0; j < kPhi; ++j) {
                const double phi = (j + 0.5) * 2 * std::numbers::pi / kPhi;
                const Spectrum l = preetham_->RadianceSpectrum(
                    Vec3f(float(r * std::cos(phi)), float(r * std::sin(phi)), float(mu)));
                for (int k = 0; k < Spectrum::kNumSamples; ++k)
                    (*e)[size_t(k)] += double(l.sample(k)) * mu * cell;
            }
        }
    } else {
        for (int k = 0; k < Spectrum::kNumSamples; ++k)
            (*e)[size_t(k)] += std::numbers::pi * radiance_.sample(k);
    }
}

double SkyLight::BrightestAxisRadiance() const {
    const SampledWavelengths green = SampledWavelengths::SampleVisible(0.5f);
    double radiance = 0;
    for (const Vec3f& w : {Vec3f(1, 0, 0), Vec3f(-1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, -1, 0),
                           Vec3f(0, 0, 1), Vec3f(0, 0, -1)})
        radiance = std::max(radiance, double(Radiance(w, green).Average()));
    return radiance;
}

double SkyLight::Power(const PhotonTarget& target) const {
    // Mean radiance over the sphere of directions (a fixed 256-direction Fibonacci set for a sky
    // model).
    double mean = 0;
    if (preetham_) {
        const int n = 256;
        for (int i = 0; i < n; ++i) {
            float z = 1 - 2 * (float(i) + 0.5f) / float(n), phi = 2.39996323f * float(i);
            float rxy = std::sqrt(std::max(0.f, 1 - z * z));
            mean +=
                MeanVisible(RadianceSpectrum(Vec3f(rxy * std::cos(phi), rxy * std::sin(phi), z)));
        }
        mean = mean / n;  // with the ground below the horizon
    } else {
        mean = MeanVisible(radiance_);
    }
    return mean * target.line_measure;
}

}  // namespace nave::render
