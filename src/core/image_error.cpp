#include "src/core/image_error.h"

#include <cmath>

#include "src/core/check.h"

namespace nave {

double FiniteMean(std::span<const float> values) {
    double sum = 0;
    size_t n = 0;
    for (float v : values) {
        if (!std::isfinite(v)) continue;
        sum += v;
        ++n;
    }
    return n > 0 ? sum / double(n) : 0.0;
}

double PairRelMse(size_t count, const std::function<std::array<double, 2>(size_t)>& pixel) {
    double mean = 0;
    size_t n = 0;
    for (size_t i = 0; i < count; ++i) {
        const std::array<double, 2> ab = pixel(i);
        if (!std::isfinite(ab[0]) || !std::isfinite(ab[1])) continue;
        mean += 0.5 * (ab[0] + ab[1]);
        ++n;
    }
    if (n == 0) return 0;
    mean /= double(n);
    const double offset = 0.01 * mean * mean;
    double sum = 0;
    for (size_t i = 0; i < count; ++i) {
        const std::array<double, 2> ab = pixel(i);
        if (!std::isfinite(ab[0]) || !std::isfinite(ab[1])) continue;
        const double m = 0.5 * (ab[0] + ab[1]);
        const double d = ab[0] - ab[1];
        const double denominator = m * m + offset;
        if (denominator > 0) sum += 0.5 * d * d / denominator;
    }
    return sum / double(n);
}

double PairRelMse(std::span<const float> a, std::span<const float> b) {
    NAVE_CHECK_EQ(a.size(), b.size());
    return PairRelMse(a.size(), [&](size_t i) { return std::array<double, 2>{a[i], b[i]}; });
}

double HalvesRelMse(std::span<const float> half0, std::span<const float> half1) {
    if (half0.empty() || half1.empty()) return std::nan("");
    return 0.5 * PairRelMse(half0, half1);
}

double HalvesRelMse(size_t count, const std::function<std::array<double, 2>(size_t)>& pixel) {
    return 0.5 * PairRelMse(count, pixel);
}

std::vector<float> BoxBlur(std::span<const float> values, int width, int height, int radius) {
    NAVE_CHECK_EQ(values.size(), size_t(width) * size_t(height));
    if (radius <= 0) return std::vector<float>(values.begin(), values.end());
    // Separable: along rows, then along columns.
    std::vector<float> rows(values.size()), out(values.size());
    for (int pass = 0; pass < 2; ++pass) {
        std::span<const float> in = pass == 0 ? values : std::span<const float>(rows);
        std::vector<float>& to = pass == 0 ? rows : out;
        for (int j = 0; j < height; ++j) {
            for (int i = 0; i < width; ++i) {
                double sum = 0;
                int n = 0;
                for (int k = -radius; k <= radius; ++k) {
                    const int x = pass == 0 ? i + k : i, y = pass == 0 ? j : j + k;
                    if (x < 0 || x >= width || y < 0 || y >= height) continue;
                    sum += in[size_t(y) * width + x];
                    ++n;
                }
                to[size_t(j) * width + i] = float(sum / n);
            }
        }
    }
    return out;
}

double RelMseAgainst(std::span<const float> image, std::span<const float> reference) {
    NAVE_CHECK_EQ(image.size(), reference.size());
    const double mean = FiniteMean(reference);
    const double offset = 0.01 * mean * mean;
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < image.size(); ++i) {
        if (!std::isfinite(image[i]) || !std::isfinite(reference[i])) continue;
        const double d = double(image[i]) - reference[i];
        const double denominator = double(reference[i]) * reference[i] + offset;
        if (denominator > 0) sum += d * d / denominator;
        ++n;
    }
    return n > 0 ? sum / double(n) : 0.0;
}

std::vector<double> RegionMeans(std::span<const float> values, int width, int height, int columns,
                                int rows) {
    NAVE_CHECK_EQ(values.size(), size_t(width) * size_t(height));
    NAVE_CHECK(columns > 0 && rows > 0);
    std::vector<double> sum(size_t(columns) * size_t(rows), 0.0);
    std::vector<size_t> count(sum.size(), 0);
    for (int y = 0; y < height; ++y) {
        const size_t row = size_t(y) * size_t(rows) / size_t(height);
        for (int x = 0; x < width; ++x) {
            const float v = values[size_t(y) * size_t(width) + size_t(x)];
            if (!std::isfinite(v)) continue;
            const size_t region =
                row * size_t(columns) + size_t(x) * size_t(columns) / size_t(width);
            sum[region] += v;
            ++count[region];
        }
    }
    for (size_t r = 0; r < sum.size(); ++r) sum[r] = count[r] > 0 ? sum[r] / double(count[r]) : 0;
    return sum;
}

}  // namespace nave
