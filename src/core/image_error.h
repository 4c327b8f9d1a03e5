#pragma once
// How noisy a render is, measured from its own samples: two estimates of the same image that differ
// only in their random numbers (two renders with different seeds, or the two halves of one render's
// samples) give an unbiased estimate of the variance of each pixel from their difference, with no
// reference image needed.

#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

namespace nave {

/// Rec. 709 / sRGB luminance of linear RGB in sRGB primaries (ITU-R BT.709-6, item 3.2).
inline double LuminanceOfLinearSrgb(double r, double g, double b) {
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
}

/// The relative mean squared error of ONE of two independent estimates `a`, `b` of the same image
/// (luminance per pixel, same size): the mean over pixels of ((a - b)^2 / 2) / (m^2 + 0.01
/// mean(m)^2) with m = (a + b) / 2. (a - b)^2 / 2 is an unbiased estimate of a pixel's variance
/// when a and b are independent and identically distributed; the 0.01 mean(m)^2 keeps black pixels
/// from dominating (the regularised relMSE of Rousselle et al. 2011, "Adaptive sampling and
/// reconstruction using greedy error minimization", with the offset relative to the image's mean).
/// For the two halves of one render's samples, the whole render's relMSE is half of this.
/// Non-finite pixels are skipped. Empty images: 0.
double PairRelMse(std::span<const float> a, std::span<const float> b);

/// The relative mean squared error of a whole render estimated from the per-pixel luminance of its
/// two halves (each the mean of half of its independent samples): PairRelMse(half0, half1) / 2,
/// since the whole render's variance is half of one half's. NaN if a half is empty.
double HalvesRelMse(std::span<const float> half0, std::span<const float> half1);
/// The same over `count` pixels whose halves `pixel(i)` gives.
double HalvesRelMse(size_t count, const std::function<std::array<double, 2>(size_t)>& pixel);

/// The relative mean squared error of `image` against `reference` (luminance, same size): the mean
/// over pixels of (image - reference)^2 / (reference^2 + 0.01 mean(reference)^2). Non-finite pixels
/// are skipped.
double RelMseAgainst(std::span<const float> image, std::span<const float> reference);

/// `values` (width x height, row-major) box-blurred over `radius` pixels around each pixel (a
/// square of 2 radius + 1 pixels a side, cut at the borders): what is left of an image once its
/// noise is averaged away.
std::vector<float> BoxBlur(std::span<const float> values, int width, int height, int radius);

/// The mean of the finite values of `values` (0 if there are none).
double FiniteMean(std::span<const float> values);

/// The means of `values` (width x height, row-major) over a grid of `columns` x `rows` regions of
/// near-equal size, top row first: a bias that covers part of an image (too dark a vault, too
/// bright a floor) shows in its regions even where the whole image's mean hides it. Non-finite
/// values are skipped; a region without a finite value has mean 0.
std::vector<double> RegionMeans(std::span<const float> values, int width, int height, int columns,
                                int rows);

}  // namespace nave
