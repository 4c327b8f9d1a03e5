#include "src/render/scene/materials/bxdf.h"

#include <complex>

namespace nave {

bool Refract(const Vec3f& wi, Vec3f n, float eta, float* etap, Vec3f* wt) {
    // Snell's law in vector form (e.g. Hecht, Optics §4.4; pbrt-v4 eq. 9.4 derivation).
    float cos_i = Dot(n, wi);
    if (cos_i < 0.f) {
        eta = 1.f / eta;
        cos_i = -cos_i;
        n = -n;
    }
    float sin2_i = std::max(0.f, 1.f - cos_i * cos_i);
    float sin2_t = sin2_i / (eta * eta);
    if (sin2_t >= 1.f) return false;
    float cos_t = std::sqrt(1.f - sin2_t);
    *wt = -wi / eta + n * (cos_i / eta - cos_t);
    if (etap) *etap = eta;
    return true;
}

FresnelPolarized FrDielectricPolarized(float cos_theta_i, float eta) {
    cos_theta_i = std::clamp(cos_theta_i, -1.f, 1.f);
    if (cos_theta_i < 0.f) {
        eta = 1.f / eta;
        cos_theta_i = -cos_theta_i;
    }
    float sin2_i = 1.f - cos_theta_i * cos_theta_i;
    float sin2_t = sin2_i / (eta * eta);
    if (sin2_t >= 1.f) return {1.f, 1.f};
    float cos_t = std::sqrt(std::max(0.f, 1.f - sin2_t));
    // Born & Wolf §1.5.2 eq. (21): amplitude ratios for s (⊥) and p (∥) polarisation.
    float r_perp = (cos_theta_i - eta * cos_t) / (cos_theta_i + eta * cos_t);
    float r_parl = (eta * cos_theta_i - cos_t) / (eta * cos_theta_i + cos_t);
    return {r_perp * r_perp, r_parl * r_parl};
}

float FrDielectric(float cos_theta_i, float eta) {
    FresnelPolarized p = FrDielectricPolarized(cos_theta_i, eta);
    return 0.5f * (p.rs + p.rp);
}

float FrComplex(float cos_theta_i, float eta, float k) {
    // Born & Wolf §14.2: the dielectric Fresnel equations hold with the complex index η̂ = η + iκ;
    // cosθt = sqrt(1 - sin²θi / η̂²) is complex. Double precision: |r|² of good conductors is close
    // to 1.
    using C = std::complex<double>;
    double cos_i = std::clamp(double(cos_theta_i), 0.0, 1.0);
    C e(eta, k);
    double sin2_i = 1.0 - cos_i * cos_i;
    C sin2_t = sin2_i / (e * e);
    C cos_t = std::sqrt(1.0 - sin2_t);
    C r_parl = (e * cos_i - cos_t) / (e * cos_i + cos_t);
    C r_perp = (cos_i - e * cos_t) / (cos_i + e * cos_t);
    return float(0.5 * (std::norm(r_parl) + std::norm(r_perp)));
}

SampledSpectrum FrComplex(float cos_theta_i, const SampledSpectrum& eta, const SampledSpectrum& k) {
    SampledSpectrum r;
    for (int i = 0; i < kNumWavelengths; ++i) r[i] = FrComplex(cos_theta_i, eta[i], k[i]);
    return r;
}

// ---- Trowbridge-Reitz

float TrowbridgeReitz::D(const Vec3f& wm) const {
    float tan2 = Tan2Theta(wm);
    if (std::isinf(tan2) || std::isnan(tan2)) return 0.f;
    float cos4 = Cos2Theta(wm) * Cos2Theta(wm);
    if (cos4 < 1e-16f) return 0.f;
    float cp = CosPhi(wm), sp = SinPhi(wm);
    // Heitz 2014 eq. (83): D = 1 / (π αx αy cos⁴θm (1 + tan²θm (cos²φ/αx² + sin²φ/αy²))²).
    float e = tan2 * (cp * cp / (alpha_x_ * alpha_x_) + sp * sp / (alpha_y_ * alpha_y_));
    return 1.f / (kPi * alpha_x_ * alpha_y_ * cos4 * (1.f + e) * (1.f + e));
}

float TrowbridgeReitz::Lambda(const Vec3f& w) const {
    float tan2 = Tan2Theta(w);
    if (std::isinf(tan2) || std::isnan(tan2)) return 0.f;
    float cp = CosPhi(w), sp = SinPhi(w);
    // Heitz 2014 eq. (86) with the anisotropic α(φ)² = cos²φ αx² + sin²φ αy² (eq. 80).
    float alpha2 = cp * cp * alpha_x_ * alpha_x_ + sp * sp * alpha_y_ * alpha_y_;
    return (std::sqrt(1.f + alpha2 * tan2) - 1.f) / 2.f;
}

float TrowbridgeReitz::D(const Vec3f& w, const Vec3f& wm) const {
    float cos_w = AbsCosTheta(w);
    if (cos_w == 0.f) return 0.f;
    return G1(w) / cos_w * D(wm) * std::abs(Dot(w, wm));
}

Vec3f TrowbridgeReitz::Sample_wm(const Vec3f& w, Point2f u) const {
    // Heitz 2018, "Sampling the GGX distribution of visible normals", §2 listing.
    // Transform the view direction to the hemisphere configuration (stretch by α).
    Vec3f vh = Normalize(Vec3f(alpha_x_ * w.x, alpha_y_ * w.y, w.z));
    if (vh.z < 0.f) vh = -vh;
    // Orthonormal basis (with a special case when vh is the pole).
    float lensq = vh.x * vh.x + vh.y * vh.y;
    Vec3f t1 = lensq > 0.f ? Vec3f(-vh.y, vh.x, 0.f) / std::sqrt(lensq) : Vec3f(1.f, 0.f, 0.f);
    Vec3f t2 = Cross(vh, t1);
    // Parameterisation of the projected area.
    float r = std::sqrt(u.x);
    float phi = 2.f * kPi * u.y;
    float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    float s = 0.5f * (1.f + vh.z);
    p2 = (1.f - s) * std::sqrt(std::max(0.f, 1.f - p1 * p1)) + s * p2;
    // Reprojection onto the hemisphere.
    Vec3f nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.f, 1.f - p1 * p1 - p2 * p2));
    // Back to the ellipsoid configuration.
    Vec3f ne(alpha_x_ * nh.x, alpha_y_ * nh.y, std::max(1e-6f, nh.z));
    return Normalize(ne);
}

// ---- Diffuse

SampledSpectrum DiffuseBxdf::Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths&,
                                  TransportMode) const {
    if (!SameHemisphere(wo, wi)) return {};
    return r_ * kInvPi;
}

std::optional<BsdfSample> DiffuseBxdf::Sample(const Vec3f& wo, float, Point2f u,
                                              const SampledWavelengths&, TransportMode) const {
    if (!r_) return std::nullopt;
    Vec3f wi = SampleCosineHemisphere(u);
    if (wo.z < 0.f) wi.z = -wi.z;
    float pdf = CosineHemispherePdf(AbsCosTheta(wi));
    if (pdf == 0.f) return std::nullopt;
    return BsdfSample{r_ * kInvPi, wi, pdf, kBxdfReflection | kBxdfDiffuse, 1.f};
}

float DiffuseBxdf::Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths&,
                       TransportMode) const {
    if (!r_ || !SameHemisphere(wo, wi)) return 0.f;
    return CosineHemispherePdf(AbsCosTheta(wi));
}

// ---- Conductor

SampledSpectrum ConductorBxdf::Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths&,
                                    TransportMode) const {
    if (!SameHemisphere(wo, wi) || distrib_.EffectivelySmooth()) return {};
    float cos_o = AbsCosTheta(wo), cos_i = AbsCosTheta(wi);
    if (cos_i == 0.f || cos_o == 0.f) return {};
    Vec3f wm = wi + wo;
    if (Dot(wm, wm) == 0.f) return {};
    wm = Normalize(wm);
    SampledSpectrum f = FrComplex(std::abs(Dot(wo, wm)), eta_, k_);
    // Walter et al. 2007 eq. (20).
    return f * (distrib_.D(wm) * distrib_.G(wo, wi) / (4.f * cos_i * cos_o));
}

std::optional<BsdfSample> ConductorBxdf::Sample(const Vec3f& wo, float, Point2f u,
                                                const SampledWavelengths&, TransportMode) const {
    if (distrib_.EffectivelySmooth()) {
        Vec3f wi(-wo.x, -wo.y, wo.z);
        float cos_i = AbsCosTheta(wi);
        if (cos_i == 0.f) return std::nullopt;
        SampledSpectrum f = FrComplex(cos_i, eta_, k_) / cos_i;
        return BsdfSample{f, wi, 1.f, kBxdfReflection | kBxdfSpecular, 1.f};
    }
    if (wo.z == 0.f) return std::nullopt;
    // Sample in the upper hemisphere and mirror back, so a path arriving from below sees the same
    // lobe.
    Vec3f wo_up = wo.z < 0.f ? -wo : wo;
    Vec3f wm = distrib_.Sample_wm(wo_up, u);
    Vec3f wi = Reflect(wo_up, wm);
    if (wi.z <= 0.f) return std::nullopt;
    // Change of variables from half vectors to reflected directions: dωm/dωi = 1/(4 |ωo·ωm|)
    // (Walter et al. 2007 eq. 14).
    float pdf = distrib_.Pdf(wo_up, wm) / (4.f * std::abs(Dot(wo_up, wm)));
    if (wo.z < 0.f) wi = -wi;
    float cos_o = AbsCosTheta(wo), cos_i = AbsCosTheta(wi);
    if (cos_i == 0.f || cos_o == 0.f || pdf == 0.f) return std::nullopt;
    SampledSpectrum f = FrComplex(std::abs(Dot(wo_up, wm)), eta_, k_) *
                        (distrib_.D(wm) * distrib_.G(wo, wi) / (4.f * cos_i * cos_o));
    return BsdfSample{f, wi, pdf, kBxdfReflection | kBxdfGlossy, 1.f};
}

float ConductorBxdf::Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths&,
                         TransportMode) const {
    if (!SameHemisphere(wo, wi) || distrib_.EffectivelySmooth()) return 0.f;
    Vec3f wm = wo + wi;
    if (Dot(wm, wm) == 0.f) return 0.f;
    wm = Normalize(wm);
    if (wm.z < 0.f) wm = -wm;
    Vec3f wo_up = wo.z < 0.f ? -wo : wo;
    return distrib_.Pdf(wo_up, wm) / (4.f * std::abs(Dot(wo_up, wm)));
}

// ---- Dielectric

bool DielectricBxdf::HalfVector(const Vec3f& wo, const Vec3f& wi, Vec3f* wm, float* etap,
                                bool* reflect) const {
    float cos_o = CosTheta(wo), cos_i = CosTheta(wi);
    if (cos_o == 0.f || cos_i == 0.f) return false;
    *reflect = cos_o * cos_i > 0.f;
    *etap = *reflect ? 1.f : (cos_o > 0.f ? eta_ : 1.f / eta_);
    // Walter et al. 2007 eq. (16): the generalized half vector h ∝ -(η_i ωi + η_o ωo), here scaled
    // so that it is ωi η' + ωo.
    Vec3f h = wi * *etap + wo;
    if (Dot(h, h) == 0.f) return false;
    h = Normalize(h);
    if (h.z < 0.f) h = -h;
    // Microfacets seen from behind by either direction carry no light.
    if (Dot(h, wi) * cos_i < 0.f || Dot(h, wo) * cos_o < 0.f) return false;
    *wm = h;
    return true;
}

SampledSpectrum DielectricBxdf::Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths&,
                                     TransportMode mode) const {
    if (eta_ == 1.f || distrib_.EffectivelySmooth()) return {};  // only delta lobes
    Vec3f wm;
    float etap;
    bool reflect;
    if (!HalfVector(wo, wi, &wm, &etap, &reflect)) return {};
    float f = FrDielectric(Dot(wo, wm), eta_);
    float cos_o = CosTheta(wo), cos_i = CosTheta(wi);
    if (reflect)
        return SampledSpectrum(distrib_.D(wm) * distrib_.G(wo, wi) * f /
                               std::abs(4.f * cos_i * cos_o));
    // Walter et al. 2007 eq. (21).
    float denom = Dot(wi, wm) + Dot(wo, wm) / etap;
    denom = denom * denom * cos_i * cos_o;
    float ft = distrib_.D(wm) * (1.f - f) * distrib_.G(wo, wi) *
               std::abs(Dot(wi, wm) * Dot(wo, wm) / denom);
    if (mode == TransportMode::kRadiance) ft /= etap * etap;
    return SampledSpectrum(ft);
}

float DielectricBxdf::Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths&,
                          TransportMode) const {
    if (eta_ == 1.f || distrib_.EffectivelySmooth()) return 0.f;
    Vec3f wm;
    float etap;
    bool reflect;
    if (!HalfVector(wo, wi, &wm, &etap, &reflect)) return 0.f;
    float r = FrDielectric(Dot(wo, wm), eta_), t = 1.f - r;
    if (reflect) return distrib_.Pdf(wo, wm) / (4.f * std::abs(Dot(wo, wm))) * r / (r + t);
    // Jacobian of the refracted half vector, Walter et al. 2007 eq. (17).
    float denom = Dot(wi, wm) + Dot(wo, wm) / etap;
    float dwm_dwi = std::abs(Dot(wi, wm)) / (denom * denom);
    return distrib_.Pdf(wo, wm) * dwm_dwi * t / (r + t);
}

std::optional<BsdfSample> DielectricBxdf::Sample(const Vec3f& wo, float uc, Point2f u,
                                                 const SampledWavelengths& lambda,
                                                 TransportMode mode) const {
    if (eta_ == 1.f || distrib_.EffectivelySmooth()) {
        float r = FrDielectric(CosTheta(wo), eta_);
        float t = 1.f - r;
        // Choose the lobe in proportion to its weight: the estimator f|cos|/pdf is then exactly 1
        // (or 1/η² for radiance through refraction), which keeps R + T = 1 without variance.
        if (uc < r / (r + t)) {
            Vec3f wi(-wo.x, -wo.y, wo.z);
            SampledSpectrum f(r / AbsCosTheta(wi));
            return BsdfSample{f, wi, r / (r + t), kBxdfReflection | kBxdfSpecular, 1.f};
        }
        Vec3f wi;
        float etap = 1.f;
        if (!Refract(wo, Vec3f(0, 0, 1), eta_, &etap, &wi)) return std::nullopt;
        SampledSpectrum f(t / AbsCosTheta(wi));
        // Radiance is compressed into a smaller solid angle on entering a denser medium (Veach 1997
        // §5.2).
        if (mode == TransportMode::kRadiance) f /= etap * etap;
        return BsdfSample{f, wi, t / (r + t), kBxdfTransmission | kBxdfSpecular, etap};
    }
    // Rough: sample a visible microfacet normal, then reflect or refract through it.
    if (wo.z == 0.f) return std::nullopt;
    Vec3f wm = distrib_.Sample_wm(wo, u);
    float r = FrDielectric(Dot(wo, wm), eta_), t = 1.f - r;
    if (uc < r / (r + t)) {
        Vec3f wi = Reflect(wo, wm);
        if (!SameHemisphere(wo, wi)) return std::nullopt;
        float pdf = distrib_.Pdf(wo, wm) / (4.f * std::abs(Dot(wo, wm))) * r / (r + t);
        SampledSpectrum f = Eval(wo, wi, lambda, mode);
        if (pdf == 0.f) return std::nullopt;
        return BsdfSample{f, wi, pdf, kBxdfReflection | kBxdfGlossy, 1.f};
    }
    Vec3f wi;
    float etap = 1.f;
    if (!Refract(wo, wm, eta_, &etap, &wi) || SameHemisphere(wo, wi) || wi.z == 0.f)
        return std::nullopt;
    wi = Normalize(wi);
    float pdf = Pdf(wo, wi, lambda, mode);
    SampledSpectrum f = Eval(wo, wi, lambda, mode);
    if (pdf == 0.f) return std::nullopt;
    return BsdfSample{f, wi, pdf, kBxdfTransmission | kBxdfGlossy, etap};
}

// ---- Thin dielectric

void ThinDielectricBxdf::ReflectanceTransmittance(float cos_theta, SampledSpectrum* r_tot,
                                                  SampledSpectrum* t_tot) const {
    cos_theta = std::clamp(std::abs(cos_theta), 0.f, 1.f);
    float sin2 = 1.f - cos_theta * cos_theta;
    for (int i = 0; i < kNumWavelengths; ++i) {
        float eta = eta_[i];
        // Path length in the pane grows as 1/cosθt (Snell: sin²θt = sin²θi / η²).
        float cos_t = std::sqrt(std::max(1e-6f, 1.f - sin2 / (eta * eta)));
        float tau = tau_[i] >= 1.f ? 1.f : std::pow(std::max(tau_[i], 0.f), 1.f / cos_t);
        // The geometric series of internal reflections (Hecht §9.7, Stokes relations) sums each
        // polarisation on its own, since reflection keeps s and p apart; unpolarised light is their
        // mean. (Averaging R first and summing one series underestimates the pane's transmittance
        // at oblique incidence: -1.5 % at 60°, -3.9 % at 76° for η = 1.52.)
        const FresnelPolarized fresnel = FrDielectricPolarized(cos_theta, eta);
        float reflected = 0.f, transmitted = 0.f;
        for (float r : {fresnel.rs, fresnel.rp}) {
            const float t = 1.f - r;
            const float denom = 1.f - r * r * tau * tau;
            if (denom <= 0.f) {
                reflected += 0.5f;
                continue;
            }
            reflected += 0.5f * (r + t * t * r * tau * tau / denom);
            transmitted += 0.5f * (t * t * tau / denom);
        }
        (*r_tot)[i] = reflected;
        (*t_tot)[i] = transmitted;
    }
}

SampledSpectrum ThinDielectricBxdf::Eval(const Vec3f&, const Vec3f&, const SampledWavelengths&,
                                         TransportMode) const {
    return {};
}

float ThinDielectricBxdf::Pdf(const Vec3f&, const Vec3f&, const SampledWavelengths&,
                              TransportMode) const {
    return 0.f;
}

std::optional<BsdfSample> ThinDielectricBxdf::Sample(const Vec3f& wo, float uc, Point2f,
                                                     const SampledWavelengths&,
                                                     TransportMode) const {
    SampledSpectrum r, t;
    ReflectanceTransmittance(AbsCosTheta(wo), &r, &t);
    float pr = r.Average(), pt = t.Average();
    if (pr + pt == 0.f) return std::nullopt;
    if (uc < pr / (pr + pt)) {
        Vec3f wi(-wo.x, -wo.y, wo.z);
        return BsdfSample{r / AbsCosTheta(wi), wi, pr / (pr + pt), kBxdfReflection | kBxdfSpecular,
                          1.f};
    }
    // Both interfaces are parallel: the ray leaves in its own direction, with no net 1/η² scaling.
    Vec3f wi = -wo;
    return BsdfSample{t / AbsCosTheta(wi), wi, pt / (pr + pt), kBxdfTransmission | kBxdfSpecular,
                      1.f};
}

}  // namespace nave
