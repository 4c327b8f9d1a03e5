#pragma once
// Counter-based random numbers for the ray streams. Every random decision of a ray is a pure
// function of (seed, pixel, sample, depth, iteration, dimension), hashed, never of thread state or
// of the order in which bricks are processed: this is what makes an image independent of the brick
// count and the thread count.

#include <cstdint>

namespace nave::render {

/// SplitMix64 finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
/// OOPSLA 2014): a bijective 64-bit mix with full avalanche.
inline constexpr uint64_t MixBits(uint64_t v) {
    v ^= v >> 30;
    v *= 0xbf58476d1ce4e5b9ull;
    v ^= v >> 27;
    v *= 0x94d049bb133111ebull;
    v ^= v >> 31;
    return v;
}

/// Combines values into one 64-bit key (order matters).
inline constexpr uint64_t HashCombine(uint64_t h, uint64_t v) {
    return MixBits(h ^ (v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2)));
}

/// The identity of one ray's random stream: which path (pixel, sample) or photon, at which depth
/// and iteration. Two rays with the same key draw the same numbers.
struct RngKey {
    uint64_t seed = 0;
    uint32_t pixel = 0;      ///< pixel index, or photon index for photons
    uint32_t sample = 0;     ///< sample index within the pixel (path mode) or 0
    uint32_t depth = 0;      ///< bounce count
    uint32_t iteration = 0;  ///< SPPM iteration or path-mode pass
    uint32_t stream = 0;     ///< 0 camera paths, 1 photons, 2 wavelengths...
};

/// Draws uniform numbers in [0, 1) for one ray vertex: `Uniform(d)` for dimension d is the same
/// whichever thread asks, and different dimensions are independent.
class VertexRng {
  public:
    explicit VertexRng(const RngKey& k) {
        uint64_t h = HashCombine(MixBits(k.seed), k.pixel);
        h = HashCombine(h, k.sample);
        h = HashCombine(h, k.depth);
        h = HashCombine(h, k.iteration);
        base_ = HashCombine(h, k.stream);
    }
    /// Uniform in [0, 1) with 24 random bits (exactly representable as float, never 1).
    float Uniform(uint32_t dimension) const {
        return float(HashCombine(base_, dimension) >> 40) * 0x1p-24f;
    }
    /// Next dimension (a running counter for code that draws a variable number of values).
    float Next() { return Uniform(counter_++); }
    uint64_t base() const { return base_; }

  private:
    uint64_t base_ = 0;
    uint32_t counter_ = 0;
};

}  // namespace nave::render
