#pragma once
// Stochastic progressive photon mapping (Hachisuka & Jensen 2009, "Stochastic progressive photon
// mapping", SIGGRAPH Asia) on the ray streams. Each iteration: camera paths stop at their first
// diffuse vertex, the visible point; photons traced through the bricks deposit their power at
// visible points within each pixel's radius; then every pixel updates its photon count N, radius R
// and flux tau (eqs. 6-8 of the paper, alpha = 2/3).
//
// Every camera path and every photon carries its own four wavelengths (hero wavelength sampling,
// Wilkie et al. 2014). A photon arriving at a visible point is evaluated at the photon's
// wavelengths: the point's BSDF (and textures) at those wavelengths, times the camera path's
// throughput there, converted to XYZ per deposit. So no two photons share a colour error, unlike
// one set of wavelengths per iteration for the whole image (pbrt-v4's SPPM), whose few photons
// through red or blue glass tint a whole gather disc. The camera throughput at the photon's
// wavelengths is exact when it does not depend on the wavelength (every point the camera sees
// directly, the usual case: throughput 1); a point seen through coloured glass or a coloured mirror
// has it interpolated linearly between the camera path's four wavelengths, an approximation of a
// smooth spectrum; a point seen through dispersive glass (the camera path kept only its hero
// wavelength) receives no photons, only its next-event estimated light.
//
// The photon estimate is a mean over iterations of each iteration's density estimate at its radius
// (unrolling eqs. 6-8: tau_N / (pi R_N^2) = sum_i phi_i / (pi R_i^2)), so the sums of the even and
// of the odd iterations are two independent estimates given the radii, whose difference estimates
// the noise (IndirectHalfY, docs/render.md "Noise").
//
// Visible points are kept per brick: a point is registered in every brick whose cell its gather
// sphere overlaps, so a photon landing in a brick finds all the points it can reach in that brick's
// own grid.

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

    /// Starts an iteration: forgets the previous visible points.
    void BeginIteration();
    /// Records pixel's visible point, with its texture coordinates `uv` (null when the mesh has
    /// none) and the camera path's throughput `beta` at its wavelengths `lambda`. Thread-safe for
    /// distinct pixels (one camera path per pixel).
    void Add(uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo,
             const SurfaceMaterial& material, const std::array<float, 2>* uv,
             const imaging::TextureFootprint& footprint, const SampledSpectrum& beta,
             const SampledWavelengths& lambda);
    /// Registers every visible point in the bricks its gather sphere overlaps (after the camera pass).
    void BuildBrickGrids(const store::BrickTree& tree);
    /// A photon of power `beta` at its wavelengths `lambda` arriving from direction `wi` (pointing
    /// away from the surface) at `p` in brick `brick`: adds the XYZ of beta * f * (camera
    /// throughput) to every visible point of that brick within its radius. Thread-safe.
    void Deposit(uint32_t brick, const Vec3f& p, const Vec3f& wi, const SampledSpectrum& beta,
                 const SampledWavelengths& lambda);
    /// Progressive update of N, R, tau of every pixel (Hachisuka & Jensen 2009 eqs. 6-8, pbrt-v4
    /// form) at the end of an iteration of half `half` (Film::SampleHalf of the iteration).
    void EndIteration(float alpha, int half);
    /// The indirect radiance estimate of `pixel` in XYZ after `photons_emitted` photons in all iterations:
    /// tau / (pi R^2 N_emitted) (Hachisuka & Jensen 2009 eq. 9).
    Vec3d IndirectXYZ(uint32_t pixel, double photons_emitted) const;
    /// The luminance of the same estimate from the iterations of half `half` alone,
    /// `photons_emitted` being the photons of those iterations.
    double IndirectHalfY(uint32_t pixel, int half, double photons_emitted) const;
    float radius(uint32_t pixel) const { return pixels_[pixel].radius; }
    uint64_t deposits() const { return deposits_.load(std::memory_order_relaxed); }

  private:
    /// How a visible point's camera throughput is known at a photon's wavelengths.
    enum class Throughput : uint8_t {
        kFlat,          // the same at every wavelength: beta_nm[0]
        kInterpolated,  // linear between (lambda_nm[i], beta_nm[i]), sorted by wavelength
        kHeroOnly,      // the camera path kept one wavelength (dispersion): no photon matches it
    };
    struct Point {
        Vec3f p, ns, wo;
        const SurfaceMaterial* material = nullptr;
        std::array<float, 2> uv{};  // texture coordinates, when has_uv
        bool has_uv = false;
        bool valid = false;
        Throughput throughput = Throughput::kFlat;
        imaging::TextureFootprint footprint;
        std::array<float, kNumWavelengths> lambda_nm{}, beta_nm{};
        /// The camera throughput at `lambda` (kFlat or kInterpolated).
        SampledSpectrum ThroughputAt(const SampledWavelengths& lambda) const;
    };
    struct PixelState {
        float radius = 0;
        double n = 0;
        Vec3d tau;
        double tau_y_half0 = 0;     // tau's luminance from the iterations of half 0
        std::atomic<float> phi[3];  // this iteration's flux, XYZ
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
    std::atomic<uint64_t> deposits_{0};
};

/// Bricks whose cells overlap `box` (kd-tree descent).
void BricksOverlapping(const store::BrickTree& tree, const Bounds3f& box, std::vector<uint32_t>* out);

}  // namespace nave::render
