#pragma once
// Stochastic progressive photon mapping (Hachisuka & Jensen 2009, "Stochastic progressive photon mapping",
// SIGGRAPH Asia) on the ray streams. Each iteration: camera paths stop at their first diffuse vertex, the
// visible point; photons traced through the bricks deposit their power at visible points within each
// pixel's radius; then every pixel updates its photon count N, radius R and flux tau (eqs. 6-8 of the paper,
// alpha = 2/3). One set of wavelengths per iteration is shared by camera paths and photons (as pbrt-v4's
// SPPM), so a photon's power and a visible point's BSDF are evaluated at the same wavelengths.
//
// Visible points are kept per brick: a point is registered in every brick whose cell its gather sphere
// overlaps, so a photon landing in a brick finds all the points it can reach in that brick's own grid.

#include <atomic>
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "core/spectrum.h"
#include "core/vecmath.h"
#include "imaging/texture_cache.h"
#include "store/brick_tree.h"

namespace nave::render {

struct SurfaceMaterial;

class VisiblePoints {
  public:
    VisiblePoints(size_t pixel_count, uint32_t brick_count, float initial_radius);

    /// Starts an iteration at wavelengths `lambda`: forgets the previous visible points.
    void BeginIteration(const SampledWavelengths& lambda);
    /// Records pixel's visible point, with its texture coordinates `uv` (null when the mesh has none).
    /// Thread-safe for distinct pixels (one camera path per pixel).
    void Add(uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo, const SurfaceMaterial& material,
             const std::array<float, 2>* uv, const imaging::TextureFootprint& footprint, const SampledSpectrum& beta);
    /// Registers every visible point in the bricks its gather sphere overlaps (after the camera pass).
    void BuildBrickGrids(const store::BrickTree& tree);
    /// A photon of power `beta` arriving from direction `wi` (pointing away from the surface) at `p` in
    /// brick `brick`: adds beta * f to every visible point of that brick within its radius. Thread-safe.
    void Deposit(uint32_t brick, const Vec3f& p, const Vec3f& ng, const Vec3f& wi, const SampledSpectrum& beta,
                 const SampledWavelengths& lambda);
    /// Progressive update of N, R, tau of every pixel (Hachisuka & Jensen 2009 eqs. 6-8, pbrt-v4 form).
    void EndIteration(float alpha);
    /// The indirect radiance estimate of `pixel` in XYZ after `photons_emitted` photons in all iterations:
    /// tau / (pi R^2 N_emitted) (Hachisuka & Jensen 2009 eq. 9).
    Vec3d IndirectXYZ(uint32_t pixel, double photons_emitted) const;
    float radius(uint32_t pixel) const { return pixels_[pixel].radius; }
    uint64_t deposits() const { return deposits_.load(std::memory_order_relaxed); }

  private:
    struct Point {
        Vec3f p, ns, wo;
        const SurfaceMaterial* material = nullptr;
        std::array<float, 2> uv{};  // texture coordinates, when has_uv
        bool has_uv = false;
        imaging::TextureFootprint footprint;
        SampledSpectrum beta;
        bool valid = false;
    };
    struct PixelState {
        float radius = 0;
        double n = 0;
        Vec3d tau;
        std::atomic<float> phi[kNumWavelengths];
        std::atomic<uint32_t> m{0};
    };
    struct BrickGrid {
        float cell = 1;
        std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
    };
    uint64_t CellKey(const Vec3f& p, float cell) const;

    std::vector<Point> points_;
    std::unique_ptr<PixelState[]> pixels_;
    size_t pixel_count_;
    std::vector<BrickGrid> grids_;
    SampledWavelengths lambda_;
    std::atomic<uint64_t> deposits_{0};
};

/// Bricks whose cells overlap `box` (kd-tree descent).
void BricksOverlapping(const store::BrickTree& tree, const Bounds3f& box, std::vector<uint32_t>* out);

}  // namespace nave::render
