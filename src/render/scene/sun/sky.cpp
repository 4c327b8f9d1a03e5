#include "src/render/scene/sun/sky.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "src/core/check.h"
#include "src/core/color.h"
#include "src/core/spectrum_data.h"

namespace nave {

namespace {

constexpr double kPiSky = std::numbers::pi;

// CIE daylight spectrum of chromaticity (x, y) (CIE 15:2004 eqs. 3.5-3.6), relative.
struct DaylightBasis {
    Spectrum s0, s1, s2;
    double y0 = 0, y1 = 0, y2 = 0;  // Σ ȳ S_i, for scaling to a luminance
    DaylightBasis() {
        const SpectraTable& t = EmbeddedSpectraTable("cie_daylight_components.csv");
        s0 = t.ToSpectrum(0);
        s1 = t.ToSpectrum(1);
        s2 = t.ToSpectrum(2);
        const Spectrum& y = CieY();
        for (int i = 0; i < Spectrum::kNumSamples; ++i) {
            y0 += double(y.sample(i)) * s0.sample(i);
            y1 += double(y.sample(i)) * s1.sample(i);
            y2 += double(y.sample(i)) * s2.sample(i);
        }
    }
};

const DaylightBasis& Basis() {
    static const DaylightBasis b;
    return b;
}

void DaylightWeights(double x, double y, double* m1, double* m2) {
    double m = 0.0241 + 0.2562 * x - 0.7341 * y;
    *m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m;
    *m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
}

}  // namespace

PreethamSky::PreethamSky(const Vec3f& sun_direction, float turbidity)
    : sun_(Normalize(sun_direction)) {
    double t = std::clamp(double(turbidity), 1.7, 10.0);
    theta_sun_ = std::acos(std::clamp(double(sun_.z), -1.0, 1.0));
    // Preetham et al. 1999, Appendix A.2: Perez coefficients as linear functions of turbidity.
    const double coef[3][5][2] = {
        // x
        {{-0.0193, -0.2592},
         {-0.0665, 0.0008},
         {-0.0004, 0.2125},
         {-0.0641, -0.8989},
         {-0.0033, 0.0452}},
        // y
        {{-0.0167, -0.2608},
         {-0.0950, 0.0092},
         {-0.0079, 0.2102},
         {-0.0441, -1.6537},
         {-0.0109, 0.0529}},
        // Y
        {{0.1787, -1.4630},
         {-0.3554, 0.4275},
         {-0.0227, 5.3251},
         {0.1206, -2.5771},
         {-0.0670, 0.3703}},
    };
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 5; ++k) perez_[c][k] = coef[c][k][0] * t + coef[c][k][1];
    // Zenith values (Appendix A.2). The sun is clamped at the horizon: the model is not defined
    // below.
    double ts = std::min(theta_sun_, kPiSky / 2);
    double chi = (4.0 / 9.0 - t / 120.0) * (kPiSky - 2.0 * ts);
    double yz_kcd = (4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192;
    double th[4] = {ts * ts * ts, ts * ts, ts, 1.0};
    const double xz[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                             {-0.02903, 0.06377, -0.03202, 0.00394},
                             {0.11693, -0.21196, 0.06052, 0.25886}};
    const double yzc[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                              {-0.04214, 0.08970, -0.04153, 0.00516},
                              {0.15346, -0.26756, 0.06670, 0.26688}};
    double tt[3] = {t * t, t, 1.0};
    double x = 0, y = 0;
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 4; ++k) {
            x += tt[r] * xz[r][k] * th[k];
            y += tt[r] * yzc[r][k] * th[k];
        }
    zenith_[0] = x;
    zenith_[1] = y;
    zenith_[2] = std::max(0.0, yz_kcd * 1000.0);  // kcd/m² -> cd/m²
}

double PreethamSky::Perez(int c, double theta, double gamma) const {
    // Perez, Seals & Michalsky (1993): F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ).
    const double* p = perez_[c];
    double cos_t = std::max(std::cos(theta), 1e-3);
    double cg = std::cos(gamma);
    return (1.0 + p[0] * std::exp(p[1] / cos_t)) *
           (1.0 + p[2] * std::exp(p[3] * gamma) + p[4] * cg * cg);
}

Vec3d PreethamSky::xyY(const Vec3f& w_in) const {
    Vec3f w = Normalize(w_in);
    if (w.z <= 0.f) return {0, 0, 0};
    double theta = std::acos(std::clamp(double(w.z), -1.0, 1.0));
    double gamma = std::acos(std::clamp(double(Dot(w, sun_)), -1.0, 1.0));
    double ts = std::min(theta_sun_, kPiSky / 2);
    Vec3d r;
    for (int c = 0; c < 3; ++c) r[c] = zenith_[c] * Perez(c, theta, gamma) / Perez(c, 0.0, ts);
    return r;
}

Spectrum PreethamSky::RadianceSpectrum(const Vec3f& w) const {
    Vec3d v = xyY(w);
    if (v.z <= 0) return Spectrum();
    const DaylightBasis& b = Basis();
    double m1, m2;
    DaylightWeights(v.x, v.y, &m1, &m2);
    // Scale so that 683 Σ ȳ L = Y (cd/m²).
    double lum = b.y0 + m1 * b.y1 + m2 * b.y2;
    double scale = lum > 0 ? v.z / (683.002 * lum) : 0.0;
    Spectrum s = b.s0 + b.s1 * float(m1) + b.s2 * float(m2);
    return s * float(scale);
}

SampledSpectrum PreethamSky::Radiance(const Vec3f& w, const SampledWavelengths& lambda) const {
    Vec3d v = xyY(w);
    if (v.z <= 0) return {};
    const DaylightBasis& b = Basis();
    double m1, m2;
    DaylightWeights(v.x, v.y, &m1, &m2);
    double lum = b.y0 + m1 * b.y1 + m2 * b.y2;
    float scale = lum > 0 ? float(v.z / (683.002 * lum)) : 0.f;
    SampledSpectrum s;
    for (int i = 0; i < kNumWavelengths; ++i) {
        float l = lambda.lambda_nm(i);
        s[i] = std::max(0.f, (b.s0.Evaluate(l) + float(m1) * b.s1.Evaluate(l) +
                              float(m2) * b.s2.Evaluate(l))) *
               scale;
    }
    return s;
}

}  // namespace nave
