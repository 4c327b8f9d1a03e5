#include "src/render/scene/lights/triangle_light.h"

#include <algorithm>

#include "src/render/scene/materials/frame.h"
#include "src/render/scene/scene.h"
#include "src/render/scene/surface_hit.h"

namespace nave::render {

std::optional<TriangleLight> TriangleLight::Make(const std::array<Vec3f, 3>& v,
                                                 const SurfaceMaterial& material,
                                                 const std::array<std::array<float, 2>, 3>* uv,
                                                 float material_power) {
    TriangleLight t;
    t.v0_ = v[0];
    t.v1_ = v[1];
    t.v2_ = v[2];
    Vec3f c = Cross(v[1] - v[0], v[2] - v[0]);
    t.area_ = 0.5f * Length(c);
    if (t.area_ <= 0) return std::nullopt;
    t.n_ = Normalize(c);
    t.material_ = &material;
    t.material_power_ = material_power;
    if (uv != nullptr) {
        t.uv_ = *uv;
        t.has_uv_ = true;
    }
    return t;
}

float TriangleLight::MaterialPower(const SurfaceMaterial& m) {
    // Any positive weight keeps the estimate unbiased; a good one only lowers noise.
    if (!(m.textures && m.textures->emission)) return MeanVisible(m.emission);
    double sum = 0;
    for (int i = 0; i < 8; ++i) {
        SampledWavelengths lambda = SampledWavelengths::SampleVisible((i + 0.5f) / 8);
        SampledSpectrum s = m.textures->MeanEmission(lambda);
        for (int k = 0; k < kNumWavelengths; ++k) sum += s[k];
    }
    // A black texture would give 0 and never be chosen; keep a floor so its triangles can still
    // emit.
    return std::max(float(sum / (8 * kNumWavelengths)), 1e-6f);
}

PhotonSample TriangleLight::SamplePhoton(const PhotonRandoms& u,
                                         const SampledWavelengths& lambda) const {
    // Uniform point on the triangle (Turk 1990 square-root parameterisation), cosine-weighted
    // direction on a side chosen with probability 1/2.
    PhotonSample s;
    const std::array<float, 3> w = SampleUniformTriangle(u.u_position);
    Vec3f p = v0_ * w[0] + v1_ * w[1] + v2_ * w[2];
    Vec3f n = u.u_side < 0.5f ? n_ : -n_;
    s.dir = Frame::FromZ(n).FromLocal(SampleCosineHemisphere(u.u_direction));
    s.origin = OffsetOrigin(p, n, s.dir);
    // L cos / (1/A * cos/pi * 1/2).
    std::array<float, 2> uv;
    for (int k = 0; k < 2; ++k) uv[k] = uv_[0][k] * w[0] + uv_[1][k] * w[1] + uv_[2][k] * w[2];
    s.power = material_->Emitted(has_uv_ ? &uv : nullptr, lambda) * (2 * kPi * area_);
    return s;
}

double TriangleLight::Power(const PhotonTarget&) const {
    // Two-sided Lambertian emitter: power = L pi A per side.
    return material_power_ * 2 * kPi * area_;
}

}  // namespace nave::render
