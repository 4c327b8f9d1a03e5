#include "src/core/image_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace nave {
namespace {

TEST(ImageErrorTest, PairRelMseOfAKnownPair) {
    // Two pixels: (1, 3) and (2, 2). m = (2, 2), mean(m) = 2, offset 0.04. Pixel 0: (a-b)^2/2 = 2
    // over 4.04; pixel 1: 0.
    const std::vector<float> a = {1, 2}, b = {3, 2};
    EXPECT_NEAR(PairRelMse(a, b), (2.0 / 4.04 + 0.0) / 2, 1e-12);
    EXPECT_NEAR(HalvesRelMse(a, b), (2.0 / 4.04) / 4, 1e-12);
    EXPECT_EQ(PairRelMse(a, a), 0.0);
}

TEST(ImageErrorTest, SkipsNonFinitePixelsAndHandlesEmptyHalves) {
    const std::vector<float> a = {1, NAN, 2}, b = {3, 1, 2};
    EXPECT_NEAR(PairRelMse(a, b), (2.0 / 4.04) / 2, 1e-12);
    EXPECT_TRUE(std::isnan(HalvesRelMse({}, b)));
    EXPECT_EQ(FiniteMean(std::vector<float>{1, INFINITY, 3}), 2.0);
}

TEST(ImageErrorTest, RelMseAgainstAReference) {
    const std::vector<float> image = {1.1f, 2}, reference = {1, 2};
    // mean(reference) = 1.5, offset 0.0225: 0.01 / 1.0225 for pixel 0.
    EXPECT_NEAR(RelMseAgainst(image, reference), (0.01 / 1.0225) / 2, 1e-6);
}

TEST(ImageErrorTest, BoxBlurAveragesTheSquareCutAtTheBorders) {
    // 3 x 2, radius 1: every pixel averages the pixels of its 3 x 3 square that exist.
    const std::vector<float> image = {0, 6, 0, 0, 0, 0};
    const std::vector<float> blurred = BoxBlur(image, 3, 2, 1);
    EXPECT_FLOAT_EQ(blurred[0], 6.f / 4);  // corner: 2 x 2 pixels
    EXPECT_FLOAT_EQ(blurred[1], 6.f / 6);  // edge: 3 x 2 pixels
    EXPECT_FLOAT_EQ(blurred[5], 6.f / 4);
    EXPECT_EQ(BoxBlur(image, 3, 2, 0), image);
}

// The point of the estimators: from two independent noisy estimates alone, PairRelMse predicts the
// error of one against the truth, and HalvesRelMse the error of their mean.
TEST(ImageErrorTest, PairEstimatePredictsTheErrorAgainstTheTruth) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> level(0.1f, 10.f);
    const size_t n = 200000;
    std::vector<float> truth(n), a(n), b(n), mean(n);
    for (size_t i = 0; i < n; ++i) {
        truth[i] = level(rng);
        // Noise with a standard deviation of 20 % of the pixel.
        std::normal_distribution<float> noise(0.f, 0.2f * truth[i]);
        a[i] = truth[i] + noise(rng);
        b[i] = truth[i] + noise(rng);
        mean[i] = 0.5f * (a[i] + b[i]);
    }
    const double actual_one = RelMseAgainst(a, truth);
    const double actual_mean = RelMseAgainst(mean, truth);
    EXPECT_NEAR(actual_one, 0.04, 0.004);  // about 0.2^2
    // Within 10 %: the pair's denominator uses the noisy m, the truth's the exact value.
    EXPECT_NEAR(PairRelMse(a, b) / actual_one, 1.0, 0.1);
    EXPECT_NEAR(HalvesRelMse(a, b) / actual_mean, 1.0, 0.1);
}

TEST(RegionMeansTest, EachRegionAveragesItsOwnPixels) {
    // 5 x 4 pixels in 2 x 2 regions of near-equal size: columns 0-2 and 3-4, rows 0-1 and 2-3.
    std::vector<float> v(20);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 5; ++x) v[size_t(y) * 5 + size_t(x)] = float(10 * (y >= 2) + (x >= 3));
    }
    v[0] = std::numeric_limits<float>::quiet_NaN();  // skipped, not a zero
    const std::vector<double> m = RegionMeans(v, 5, 4, 2, 2);
    ASSERT_EQ(m.size(), 4u);
    EXPECT_EQ(m[0], 0.0);   // top left (its NaN skipped)
    EXPECT_EQ(m[1], 1.0);   // top right
    EXPECT_EQ(m[2], 10.0);  // bottom left
    EXPECT_EQ(m[3], 11.0);  // bottom right
    // One region: the image's mean.
    EXPECT_DOUBLE_EQ(RegionMeans(v, 5, 4, 1, 1)[0], FiniteMean(v));
}

}  // namespace
}  // namespace nave
