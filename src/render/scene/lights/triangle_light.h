#pragma once
// An emissive triangle: a two-sided Lambertian emitter of its material's radiance (an emission
// spectrum or texture). Paths find it by hitting it; next-event estimation does not sample it;
// photons leave it (PhotonEmitters gathers one per triangle of an emissive material).

#include <array>
#include <optional>

#include "src/render/scene/lights/light.h"

namespace nave::render {

struct SurfaceMaterial;

class TriangleLight final : public Light {
  public:
    /// The triangle `v` of emissive `material` (which must outlive it), with texture coordinates
    /// `uv` of its vertices if the mesh has them, and `material_power`, MaterialPower of its
    /// material; nothing for a triangle of no area.
    static std::optional<TriangleLight> Make(const std::array<Vec3f, 3>& v,
                                             const SurfaceMaterial& material,
                                             const std::array<std::array<float, 2>, 3>* uv,
                                             float material_power);
    /// The rough power per unit area and side of an emissive material for choosing emitters:
    /// MeanVisible of its spectrum, or for an emission texture the mean of its mean radiance over a
    /// few wavelength sets.
    static float MaterialPower(const SurfaceMaterial& m);

    PhotonSample SamplePhoton(const PhotonRandoms& u,
                              const SampledWavelengths& lambda) const override;
    double Power(const PhotonTarget& target) const override;

  private:
    TriangleLight() : Light(LightKind::kTriangle) {}
    Vec3f v0_, v1_, v2_, n_;
    float area_ = 0;
    float material_power_ = 0;
    const SurfaceMaterial* material_ = nullptr;  // what it emits
    std::array<std::array<float, 2>, 3> uv_{};   // texture coordinates of v0, v1, v2
    bool has_uv_ = false;
};

}  // namespace nave::render
