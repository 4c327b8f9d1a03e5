#pragma once
// Progressive photon mapping on the ray streams, with stochastic visible points (Hachisuka & Jensen
// 2009, "Stochastic progressive photon mapping") and the radius schedule of probabilistic
// progressive photon mapping (Knaus & Zwicker 2011, "Progressive photon mapping: a probabilistic
// approach", eq. 16: r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1), alpha = 2/3). Each iteration: camera
// paths stop at their first diffuse vertex, the visible point; photons traced through the bricks
// deposit their power at visible points within the iteration's radius r_i; the pixel adds phi_i /
// (pi r_i^2). The estimate is the mean of these independent density estimates over iterations,
// photons per iteration N_p: L = sum_i phi_i / (pi r_i^2 N_p) / iterations. The radius depends on
// the iteration only, not on the photons found so far (unlike Hachisuka & Jensen's per-pixel N and
// R), so iterations are independent and the sums of the even and of the odd iterations are two
// independent estimates, whose difference measures the noise exactly (IndirectHalfY, docs/render.md
// "Noise").
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
// smooth spectrum. A point seen through dispersive glass keeps only one wavelength, the camera
// path's hero, which almost no photon carries: so every iteration has kWavelengthChannels sets of
// wavelengths of its own (IterationWavelengths), a camera path meeting dispersive glass with a
// throughput still the same at every wavelength takes its pixel's channel's (nothing it did so far
// depended on its own, so the swap keeps it unbiased), and one photon in kSharedWavelengthEvery
// carries one channel's too. Those photons light only the points of their channel, at its hero
// wavelength, the others only the other points, each set weighted by the share of the photons it
// is. (pbrt-v4's SPPM, whose photons all share one set of wavelengths per iteration, lights such
// points with all; sharing them all would bring back the colour blotches, and one set per iteration
// would tint every point seen through the glass alike.) A point seen
// through coloured glass and then dispersive glass (its throughput no longer flat when it met the
// dispersion) still receives no photons, only its next-event estimated light.

//
// Visible points are kept per brick: a point is registered in every brick whose cell its gather
// sphere overlaps, so a photon landing in a brick finds all the points it can reach in that brick's
// own grid. In a distributed render (docs/distributed.md) a point is made by the process that owns
// the brick the camera path stopped in, which sends it to the owners of the other bricks its sphere
// overlaps; each process registers points in its own bricks only, and its pixels' density sums
// hold the deposits it made: the image's are their sums over the processes.
//
// With final gathering (render.final_gather) the visible point lies one bounce past the first
// diffuse vertex, and light reaching that vertex through a chain of specular bounces (a caustic:
// sunlight through a glass ball, off a mirror) is found neither by its next-event estimation nor,
// but by chance, by the gather bounce. So, as in Jensen 1996 ("Global illumination using photon
// maps", 3.3: caustics from a separate map, seen directly), each pixel then has a second, caustic
// point at the first diffuse vertex that takes only the photons whose every bounce was specular
// (kSpecularChain), and a gathering path that finds light at the end of a specular chain drops it
// (the caustic point has it). Only scenes with a material that makes caustics
// (SurfaceMaterial::MakesCaustics) have them.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include "src/core/byte_stream.h"
#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/imaging/texture_cache.h"
#include "store/brick_tree.h"

namespace nave::render {

struct SurfaceMaterial;
struct RenderSettings;
class RankGroup;

class VisiblePoints {
  public:
    /// `initial_radius`: r_1 in metres; `alpha`: the schedule's alpha in (0, 1];
    /// `caustic_points`: a caustic point per pixel besides its visible point (UsesCausticPoints).
    VisiblePoints(size_t pixel_count, uint32_t brick_count, float initial_radius, float alpha,
                  bool caustic_points = false);

    /// The bytes the visible points of `pixel_count` pixels take: a point (two with
    /// `caustic_points`) and a pixel state each, and the points' references in the brick grids (a
    /// gather sphere overlaps up to 8 cells of the grid, whose vectors grow by doubling).
    static uint64_t MemoryBytes(uint64_t pixel_count, bool caustic_points) {
        const uint64_t per_point = sizeof(Point) + 2 * 8 * sizeof(uint32_t) + 32;
        return pixel_count * (sizeof(PixelState) + per_point * (caustic_points ? 2 : 1));
    }
    bool caustic_points() const { return points_.size() > pixel_count_; }

    /// Starts iteration `iteration` of `photons` photons (its shared wavelengths are
    /// IterationWavelengths(seed, iteration, channel)): forgets the previous visible points.
    void BeginIteration(uint64_t seed, uint32_t iteration, uint64_t photons);
    /// The shared-wavelength channel of photon `index` of an iteration of `photons` (one photon in
    /// kSharedWavelengthEvery, with at least two per channel), or kOwnWavelengths.
    static int PhotonChannel(uint64_t index, uint64_t photons) {
        if (photons < 2 * kSharedWavelengthEvery * kWavelengthChannels) return kOwnWavelengths;
        if (index % kSharedWavelengthEvery != 0) return kOwnWavelengths;
        return int(index / kSharedWavelengthEvery % kWavelengthChannels);
    }
    /// The shared-wavelength channel of the camera path of `pixel`.
    static int PixelChannel(uint32_t pixel) { return int(pixel % kWavelengthChannels); }
    /// Records pixel's visible point, with its texture coordinates `uv` (null when the mesh has
    /// none) and the camera path's throughput `beta` at its wavelengths `lambda`. Thread-safe for
    /// distinct pixels (one camera path per pixel).
    void Add(uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo,
             const SurfaceMaterial& material, const std::array<float, 2>* uv,
             const imaging::TextureFootprint& footprint, const SampledSpectrum& beta,
             const SampledWavelengths& lambda);
    /// Records pixel's caustic point (as Add; only with caustic_points()): the first diffuse
    /// vertex of a gathering camera path, lit by caustic photons only.
    void AddCaustic(uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo,
                    const SurfaceMaterial& material, const std::array<float, 2>* uv,
                    const imaging::TextureFootprint& footprint, const SampledSpectrum& beta,
                    const SampledWavelengths& lambda);
    /// In a distributed render, after the camera pass: sends each visible point this process made
    /// to the processes owning a brick its gather sphere overlaps (`owner` of a brick), and keeps
    /// the points the others send, so that every photon traced here finds every point it can
    /// reach. `materials`: the scene's, which the points refer to. Collective. Errors: the
    /// exchange's, and a received point that names no pixel or material (InternalError).
    Status ShareWithOwners(RankGroup& ranks, const store::BrickTree& tree,
                           const std::function<int(uint32_t brick)>& owner,
                           std::span<const SurfaceMaterial> materials);
    /// Registers every visible point in the bricks its gather sphere overlaps (after the camera
    /// pass), of those `keep` accepts (empty: all; in a distributed render, this process's).
    void BuildBrickGrids(const store::BrickTree& tree,
                         const std::function<bool(uint32_t brick)>& keep = {});
    /// A photon of power `beta` at its wavelengths `lambda` arriving from direction `wi` (pointing
    /// away from the surface) at `p`, on a surface of geometric normal `ng`, in brick `brick`: adds
    /// the XYZ of beta * f * (camera throughput) to every visible point of that brick within the
    /// radius whose surface faces the same way (|ng . ns| >= kSameSurfaceCos); returns the
    /// luminance it added. Thread-safe.
    /// `channel`: PhotonChannel of the photon; one on shared wavelengths lights only the points
    /// seen through dispersive glass of its channel. `caustic`: the photon's every bounce was
    /// specular (kSpecularChain); only such photons light caustic points.
    float Deposit(uint32_t brick, const Vec3f& p, const Vec3f& ng, const Vec3f& wi,
                  const SampledSpectrum& beta, const SampledWavelengths& lambda, int channel,
                  bool caustic = false);
    /// A photon counts at a visible point only if their surfaces are within ~70 degrees of each
    /// other: the density estimate divides by the area of a flat disc, so photons on a wall must
    /// not add to the floor in the corner below it (Jensen 2001, "Realistic image synthesis using
    /// photon mapping", 7.2, on gathering from other surfaces). A tighter test would also drop the
    /// photons of a curved surface within the radius (pillars, vaults): on the abbey at a radius of
    /// 0.4 m the mean was 3.7 % over the path-traced one with no test, 1.6 % under with this one,
    /// 10 % under at 45 degrees.
    static constexpr float kSameSurfaceCos = 0.3f;
    /// Adds the iteration's density estimate phi / (pi r^2) of every pixel, counted in half `half`
    /// (Film::SampleHalf of the iteration), and shrinks the radius for the next iteration.
    void EndIteration(int half);
    /// The indirect radiance estimate of `pixel` in XYZ after `photons_emitted` photons in all
    /// iterations: sum_i phi_i / (pi r_i^2) / photons_emitted.
    Vec3d IndirectXYZ(uint32_t pixel, double photons_emitted) const;
    /// The luminance of the same estimate from the iterations of half `half` alone,
    /// `photons_emitted` being the photons of those iterations.
    double IndirectHalfY(uint32_t pixel, int half, double photons_emitted) const;
    /// Between two iterations (after EndIteration): appends the radius, the iteration and every
    /// pixel's sums to `out`, for a checkpoint. The visible points themselves are remade by each
    /// iteration and are not saved.
    void SaveState(ByteWriter* out) const;
    /// Replaces what SaveState saved. Errors: DataLoss for another pixel count or truncated bytes.
    Status LoadState(ByteReader* in);
    /// In a distributed render, where each process holds the density sums of the deposits it
    /// made: replaces them by their sums over the processes (`sum`), in every process.
    Status CombineSums(const std::function<Status(std::span<double>)>& sum);
    /// Forgets the density sums (radius and iteration stay): a process whose sums another holds.
    void ClearSums();
    /// The gather radius of the current iteration (metres).
    float radius() const { return radius_; }
    uint64_t deposits() const { return deposits_.load(std::memory_order_relaxed); }

    /// One photon in this many carries shared wavelengths, of one of kWavelengthChannels sets per
    /// iteration.
    static constexpr uint32_t kSharedWavelengthEvery = 8;
    static constexpr uint32_t kWavelengthChannels = 16;
    static constexpr int kOwnWavelengths = -1;

  private:
    /// How a visible point's camera throughput is known at a photon's wavelengths.
    enum class Throughput : uint8_t {
        kFlat,          // the same at every wavelength: beta_nm[0]
        kInterpolated,  // linear between (lambda_nm[i], beta_nm[i]), sorted by wavelength
        kHeroShared,    // the camera path kept the iteration's shared hero wavelength (dispersion):
                        // beta_nm[0] there, lit by the photons on the shared wavelengths
        kHeroOnly,      // the camera path kept a hero wavelength of its own: no photon matches it
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
        Vec3d density_sum;               // sum over iterations of phi_i / (pi r_i^2), XYZ
        double density_sum_y_half0 = 0;  // the same in luminance over the iterations of half 0
        // This iteration's flux, XYZ: in double, so that the order in which threads (and the
        // processes of a distributed render) add their deposits hardly ever shows in the image.
        std::atomic<double> phi[3];
    };
    struct BrickGrid {
        float cell = 1;
        std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
    };
    uint64_t CellKey(const Vec3f& p, float cell) const;
    /// The box around `p` that its gather sphere of the current radius fits in.
    Bounds3f GatherBox(const Vec3f& p) const;
    void Set(Point* point, uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo,
             const SurfaceMaterial& material, const std::array<float, 2>* uv,
             const imaging::TextureFootprint& footprint, const SampledSpectrum& beta,
             const SampledWavelengths& lambda);

    std::vector<Point> points_;  // the pixels' visible points, then their caustic points if any
    std::array<SampledWavelengths, kWavelengthChannels> shared_lambda_;  // the iteration's
    // How many photons each photon on a channel's shared wavelengths, and each other one, stands
    // for.
    std::array<float, kWavelengthChannels> shared_weight_{};
    float own_weight_ = 1;
    std::unique_ptr<PixelState[]> pixels_;
    size_t pixel_count_;
    float radius_;
    float alpha_;
    int iteration_ = 1;  // 1-based, as in Knaus & Zwicker's schedule
    std::vector<BrickGrid> grids_;
    std::atomic<uint64_t> deposits_{0};
};

/// The wavelengths of shared-wavelength channel `channel` of an iteration of photon mode
/// (visible_points.h): the same for all its camera paths and photons that take them, a sample of
/// the visible distribution drawn from (seed, iteration, channel).
SampledWavelengths IterationWavelengths(uint64_t seed, uint32_t iteration, int channel);

/// Whether photon mode with final gathering keeps caustic points: some material of `materials`
/// makes caustics (visible_points.h).
bool UsesCausticPoints(const RenderSettings& settings,
                       const std::vector<SurfaceMaterial>& materials);

}  // namespace nave::render
