#pragma once
// BxDFs: the scattering functions nave builds at each hit, as small value types (no heap),
// evaluated in a local frame where the shading normal is +z. Materials (materials.h) own the
// spectra and build a Bxdf per hit for the path's wavelengths; Bsdf adds the world <-> local frame.
//
// Conventions (as pbrt-v4): wo and wi point away from the surface, both unit length. Eval returns
// f(wo, wi) without the cosine factor. Sample returns f, wi and the pdf of wi (for specular lobes
// the probability of choosing the lobe, and f includes the delta's 1/|cosθi|), so that f |cosθi| /
// pdf is the path weight in every case. Pdf and Eval of specular lobes are 0.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <variant>

#include "src/core/sampling.h"
#include "src/core/spectrum.h"
#include "src/core/vecmath.h"
#include "src/render/scene/materials/frame.h"

namespace nave {

/// Whether a path carries radiance (from the camera) or importance (from lights): refraction scales
/// radiance by 1/η², not importance (Veach 1997, §5.2).
enum class TransportMode : uint8_t { kRadiance, kImportance };

/// Kinds of lobes, combined as bits.
enum BxdfFlags : uint8_t {
    kBxdfUnset = 0,
    kBxdfReflection = 1 << 0,
    kBxdfTransmission = 1 << 1,
    kBxdfDiffuse = 1 << 2,
    kBxdfGlossy = 1 << 3,
    kBxdfSpecular = 1 << 4,
};

/// A sampled direction.
struct BsdfSample {
    /// f(wo, wi) (for specular lobes: the delta's weight over |cosθi|).
    SampledSpectrum f;
    /// The sampled incident direction (local frame in BxDFs, world frame from Bsdf).
    Vec3f wi;
    /// Solid-angle pdf of wi, or the probability of a specular lobe.
    float pdf = 0;
    /// BxdfFlags of the lobe sampled.
    uint8_t flags = kBxdfUnset;
    /// Relative index of refraction η_t/η_i across a transmission (1 otherwise); paths track η² for
    /// Russian roulette.
    float eta = 1;

    bool IsReflection() const { return flags & kBxdfReflection; }
    bool IsTransmission() const { return flags & kBxdfTransmission; }
    bool IsSpecular() const { return flags & kBxdfSpecular; }
    bool IsDiffuse() const { return flags & kBxdfDiffuse; }
    bool IsGlossy() const { return flags & kBxdfGlossy; }
};

// ---- Local-frame trigonometry (normal = +z)

inline float CosTheta(const Vec3f& w) { return w.z; }
inline float AbsCosTheta(const Vec3f& w) { return std::abs(w.z); }
inline float Cos2Theta(const Vec3f& w) { return w.z * w.z; }
inline float Sin2Theta(const Vec3f& w) { return std::max(0.f, 1.f - w.z * w.z); }
inline float Tan2Theta(const Vec3f& w) { return Sin2Theta(w) / Cos2Theta(w); }
inline float CosPhi(const Vec3f& w) {
    float s = std::sqrt(Sin2Theta(w));
    return s == 0.f ? 1.f : std::clamp(w.x / s, -1.f, 1.f);
}
inline float SinPhi(const Vec3f& w) {
    float s = std::sqrt(Sin2Theta(w));
    return s == 0.f ? 0.f : std::clamp(w.y / s, -1.f, 1.f);
}
inline bool SameHemisphere(const Vec3f& a, const Vec3f& b) { return a.z * b.z > 0.f; }
/// Mirror of wo about n.
inline Vec3f Reflect(const Vec3f& wo, const Vec3f& n) { return -wo + n * (2.f * Dot(wo, n)); }
/// Refraction of wi (pointing away from the surface) through the interface of normal n and relative
/// index eta = η_t/η_i (η of the side n points away from, over the side wi is on when wi·n > 0).
/// Returns false on total internal reflection. *etap receives the relative index actually crossed.
bool Refract(const Vec3f& wi, Vec3f n, float eta, float* etap, Vec3f* wt);

// ---- Fresnel

/// Unpolarised Fresnel reflectance of a dielectric interface for relative index eta = η_t/η_i and
/// cosθi (negative: the ray arrives from the η_t side, and eta is inverted). 1 under total internal
/// reflection. Fresnel equations, e.g. Born & Wolf, Principles of Optics, 7th ed., §1.5.2 eq. (21).
float FrDielectric(float cos_theta_i, float eta);
/// The s- (perpendicular) and p- (parallel) polarised reflectances |r_s|², |r_p|² of a dielectric.
struct FresnelPolarized {
    float rs = 0, rp = 0;
};
FresnelPolarized FrDielectricPolarized(float cos_theta_i, float eta);
/// Exact unpolarised Fresnel reflectance of a conductor of complex relative index η + iκ for
/// cosθi in [0, 1]: the Fresnel equations with a complex refractive index (Born & Wolf §14.2, eqs.
/// (14.2.5)-(14.2.9); no Schlick approximation).
float FrComplex(float cos_theta_i, float eta, float k);
SampledSpectrum FrComplex(float cos_theta_i, const SampledSpectrum& eta, const SampledSpectrum& k);

// ---- Microfacets

/// Perceptual roughness in [0, 1] -> GGX α = roughness² (Burley 2012, "Physically-based shading at
/// Disney", §5.4).
inline float RoughnessToAlpha(float roughness) { return roughness * roughness; }

/// The anisotropic Trowbridge-Reitz (GGX) distribution of microfacet normals (Trowbridge & Reitz
/// 1975; Walter et al. 2007), with Smith's height-correlated masking-shadowing (Heitz 2014,
/// "Understanding the masking-shadowing function in microfacet-based BRDFs", JCGT 3(2)) and
/// visible-normal sampling (Heitz 2018, "Sampling the GGX distribution of visible normals", JCGT
/// 7(4)).
class TrowbridgeReitz {
  public:
    TrowbridgeReitz() = default;
    TrowbridgeReitz(float alpha_x, float alpha_y) : alpha_x_(alpha_x), alpha_y_(alpha_y) {}

    /// Below this α the surface is treated as a perfect mirror (a delta lobe) to avoid precision
    /// loss.
    bool EffectivelySmooth() const { return std::max(alpha_x_, alpha_y_) < 1e-3f; }
    /// D(ωm): the density of normals per unit projected area (Heitz 2014 eq. 83 anisotropic form).
    float D(const Vec3f& wm) const;
    /// Smith's Λ(ω) (Heitz 2014 eq. 86).
    float Lambda(const Vec3f& w) const;
    float G1(const Vec3f& w) const { return 1.f / (1.f + Lambda(w)); }
    /// Height-correlated masking-shadowing G2 (Heitz 2014 eq. 99).
    float G(const Vec3f& wo, const Vec3f& wi) const {
        return 1.f / (1.f + Lambda(wo) + Lambda(wi));
    }
    /// The distribution of visible normals D_ω(ωm) = G1(ω) max(0, ω·ωm) D(ωm) / cosθ (Heitz 2018
    /// eq. 1); the pdf of Sample_wm.
    float D(const Vec3f& w, const Vec3f& wm) const;
    float Pdf(const Vec3f& w, const Vec3f& wm) const { return D(w, wm); }
    /// Samples a visible normal for direction w (Heitz 2018, listing in §2).
    Vec3f Sample_wm(const Vec3f& w, Point2f u) const;

    float alpha_x() const { return alpha_x_; }
    float alpha_y() const { return alpha_y_; }

  private:
    float alpha_x_ = 0, alpha_y_ = 0;
};

// ---- BxDFs

/// Lambertian reflection with spectral albedo R: f = R/π, cosine-weighted sampling.
class DiffuseBxdf {
  public:
    DiffuseBxdf() = default;
    explicit DiffuseBxdf(const SampledSpectrum& r) : r_(r) {}

    SampledSpectrum Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
                         TransportMode mode = TransportMode::kRadiance) const;
    std::optional<BsdfSample> Sample(const Vec3f& wo, float uc, Point2f u,
                                     const SampledWavelengths& lambda,
                                     TransportMode mode = TransportMode::kRadiance) const;
    float Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
              TransportMode mode = TransportMode::kRadiance) const;
    uint8_t Flags() const { return r_ ? kBxdfReflection | kBxdfDiffuse : kBxdfUnset; }

  private:
    SampledSpectrum r_;
};

/// A metal: complex index η + iκ per wavelength with the exact conductor Fresnel equations; a
/// perfect mirror when the distribution is effectively smooth, else a Trowbridge-Reitz microfacet
/// BRDF f = D(ωm) F(ωo·ωm) G(ωo, ωi) / (4 cosθo cosθi) (Walter et al. 2007 eq. 20) sampled with
/// visible normals.
class ConductorBxdf {
  public:
    ConductorBxdf() = default;
    ConductorBxdf(const TrowbridgeReitz& distrib, const SampledSpectrum& eta,
                  const SampledSpectrum& k)
        : distrib_(distrib), eta_(eta), k_(k) {}

    SampledSpectrum Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
                         TransportMode mode = TransportMode::kRadiance) const;
    std::optional<BsdfSample> Sample(const Vec3f& wo, float uc, Point2f u,
                                     const SampledWavelengths& lambda,
                                     TransportMode mode = TransportMode::kRadiance) const;
    float Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
              TransportMode mode = TransportMode::kRadiance) const;
    uint8_t Flags() const {
        return kBxdfReflection | (distrib_.EffectivelySmooth() ? kBxdfSpecular : kBxdfGlossy);
    }

  private:
    TrowbridgeReitz distrib_;
    SampledSpectrum eta_, k_;
};

/// An interface between dielectrics of relative index eta (inside over outside; the normal points
/// outside). Smooth (a delta lobe pair) when the distribution is effectively smooth: Fresnel
/// reflection and refraction chosen in proportion to R and T = 1 - R, so that R + T = 1 exactly.
/// Rough otherwise: the Trowbridge-Reitz microfacet BTDF of Walter, Marschner, Li & Torrance 2007
/// ("Microfacet models for refraction through rough surfaces", eqs. 20-21) with visible-normal
/// sampling (Heitz 2018), e.g. for uneven medieval glass. Dispersion: the material passes the index
/// at the hero wavelength and terminates the secondary wavelengths (see DielectricMaterial).
/// Absorption inside (Beer-Lambert) is a property of the volume the refracted path crosses, not of
/// the interface: see DielectricMaterial.
class DielectricBxdf {
  public:
    DielectricBxdf() = default;
    explicit DielectricBxdf(float eta, const TrowbridgeReitz& distrib = TrowbridgeReitz())
        : eta_(eta), distrib_(distrib) {}

    SampledSpectrum Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
                         TransportMode mode = TransportMode::kRadiance) const;
    std::optional<BsdfSample> Sample(const Vec3f& wo, float uc, Point2f u,
                                     const SampledWavelengths& lambda,
                                     TransportMode mode = TransportMode::kRadiance) const;
    float Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
              TransportMode mode = TransportMode::kRadiance) const;
    uint8_t Flags() const {
        uint8_t kind = distrib_.EffectivelySmooth() ? kBxdfSpecular : kBxdfGlossy;
        return eta_ == 1.f ? kBxdfTransmission | kind : kBxdfReflection | kBxdfTransmission | kind;
    }
    float eta() const { return eta_; }
    const TrowbridgeReitz& distribution() const { return distrib_; }

  private:
    /// The generalized half vector of (wo, wi) facing +z, the relative index across and whether it
    /// is a reflection; false if the pair has no valid microfacet.
    bool HalfVector(const Vec3f& wo, const Vec3f& wi, Vec3f* wm, float* etap, bool* reflect) const;

    float eta_ = 1.5f;
    TrowbridgeReitz distrib_;
};

/// A thin pane of glass (window): two parallel interfaces of index eta(λ) with an absorbing
/// interior of internal transmittance tau(λ) at normal incidence (one pass). Light leaves either
/// mirrored or straight through (the pane is thin: no lateral shift). The infinite series of
/// internal reflections is summed in closed form (Stokes 1862; e.g. Hecht, Optics, 5th ed., §9.7;
/// pbrt-v4 §9.5.2 without absorption):
///   R_tot = R + T² R τ² / (1 - R² τ²),   T_tot = T² τ / (1 - R² τ²),
/// with R = Fresnel at the angle of incidence, T = 1 - R and τ = tau^(1/cosθt) for the slanted
/// path.
class ThinDielectricBxdf {
  public:
    ThinDielectricBxdf() = default;
    ThinDielectricBxdf(const SampledSpectrum& eta, const SampledSpectrum& tau)
        : eta_(eta), tau_(tau) {}

    /// The total reflectance and transmittance for a direction with |cosθ| = cos_theta.
    void ReflectanceTransmittance(float cos_theta, SampledSpectrum* r, SampledSpectrum* t) const;

    SampledSpectrum Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
                         TransportMode mode = TransportMode::kRadiance) const;
    std::optional<BsdfSample> Sample(const Vec3f& wo, float uc, Point2f u,
                                     const SampledWavelengths& lambda,
                                     TransportMode mode = TransportMode::kRadiance) const;
    float Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
              TransportMode mode = TransportMode::kRadiance) const;
    uint8_t Flags() const { return kBxdfReflection | kBxdfTransmission | kBxdfSpecular; }

  private:
    SampledSpectrum eta_{1.5f}, tau_{1.f};
};

/// Any of nave's BxDFs, as a tagged value (std::variant): no heap, cheap to build per hit.
class Bxdf {
  public:
    using Variant = std::variant<DiffuseBxdf, ConductorBxdf, DielectricBxdf, ThinDielectricBxdf>;

    Bxdf() = default;
    template <typename T>
    Bxdf(const T& b) : v_(b) {}  // NOLINT: implicit from any concrete BxDF by design

    SampledSpectrum Eval(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
                         TransportMode mode = TransportMode::kRadiance) const {
        return std::visit([&](const auto& b) { return b.Eval(wo, wi, lambda, mode); }, v_);
    }
    std::optional<BsdfSample> Sample(const Vec3f& wo, float uc, Point2f u,
                                     const SampledWavelengths& lambda,
                                     TransportMode mode = TransportMode::kRadiance) const {
        return std::visit([&](const auto& b) { return b.Sample(wo, uc, u, lambda, mode); }, v_);
    }
    float Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda,
              TransportMode mode = TransportMode::kRadiance) const {
        return std::visit([&](const auto& b) { return b.Pdf(wo, wi, lambda, mode); }, v_);
    }
    uint8_t Flags() const {
        return std::visit([](const auto& b) { return b.Flags(); }, v_);
    }
    const Variant& variant() const { return v_; }

  private:
    Variant v_;
};

/// A Bxdf in the world: the shading frame plus the local BxDF. All directions here are world-space.
class Bsdf {
  public:
    Bsdf() = default;
    /// `shading_normal` unit length; `tangent` optional (anisotropy direction), may be zero.
    Bsdf(const Vec3f& shading_normal, const Vec3f& tangent, const Bxdf& bxdf)
        : frame_(Frame::FromZTangent(shading_normal, tangent)), bxdf_(bxdf) {}
    Bsdf(const Frame& frame, const Bxdf& bxdf) : frame_(frame), bxdf_(bxdf) {}

    /// The surface's geometric normal (not necessarily unit length). Where it and the shading
    /// normal disagree on whether a direction pair is a reflection or a transmission, the BSDF is
    /// zero (Veach 1997, "Robust Monte Carlo methods for light transport simulation", §5.3.2):
    /// otherwise a reflection the bent normal allows would pass through the surface, and light
    /// through a closed wall.
    void SetGeometricNormal(const Vec3f& ng) { ng_ = ng; }

    SampledSpectrum Eval(const Vec3f& wo_world, const Vec3f& wi_world,
                         const SampledWavelengths& lambda,
                         TransportMode mode = TransportMode::kRadiance) const {
        Vec3f wo = frame_.ToLocal(wo_world), wi = frame_.ToLocal(wi_world);
        if (wo.z == 0.f) return {};
        if (!SidesAgree(wo_world, wi_world, wo, wi)) return {};
        return bxdf_.Eval(wo, wi, lambda, mode);
    }
    std::optional<BsdfSample> Sample(const Vec3f& wo_world, float uc, Point2f u,
                                     const SampledWavelengths& lambda,
                                     TransportMode mode = TransportMode::kRadiance) const {
        Vec3f wo = frame_.ToLocal(wo_world);
        if (wo.z == 0.f || !bxdf_.Flags()) return std::nullopt;
        std::optional<BsdfSample> s = bxdf_.Sample(wo, uc, u, lambda, mode);
        if (!s || !s->f || s->pdf == 0.f || s->wi.z == 0.f) return std::nullopt;
        const Vec3f wi_world = frame_.FromLocal(s->wi);
        if (!SidesAgree(wo_world, wi_world, wo, s->wi)) return std::nullopt;
        s->wi = wi_world;
        return s;
    }
    float Pdf(const Vec3f& wo_world, const Vec3f& wi_world, const SampledWavelengths& lambda,
              TransportMode mode = TransportMode::kRadiance) const {
        Vec3f wo = frame_.ToLocal(wo_world), wi = frame_.ToLocal(wi_world);
        if (wo.z == 0.f) return 0.f;
        return bxdf_.Pdf(wo, wi, lambda, mode);
    }
    uint8_t Flags() const { return bxdf_.Flags(); }
    const Frame& frame() const { return frame_; }
    const Bxdf& bxdf() const { return bxdf_; }

  private:
    /// Whether the geometric normal, if set, sees the pair on the sides the shading frame does.
    bool SidesAgree(const Vec3f& wo_world, const Vec3f& wi_world, const Vec3f& wo,
                    const Vec3f& wi) const {
        if (ng_.x == 0.f && ng_.y == 0.f && ng_.z == 0.f) return true;
        const bool geometric_reflection = Dot(wo_world, ng_) * Dot(wi_world, ng_) > 0;
        return geometric_reflection == (wo.z * wi.z > 0);
    }

    Frame frame_;
    Bxdf bxdf_;
    Vec3f ng_{0, 0, 0};  ///< 0: not set
};

}  // namespace nave
