#include "core/image_error.h"

#include <cmath>

#include "core/check.h"

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

double PairRelMse(std::span<const float> a, std::span<const float> b) {
    NAVE_CHECK_EQ(a.size(), b.size());
    double mean = 0;
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (!std::isfinite(a[i]) || !std::isfinite(b[i])) continue;
        mean += 0.5 * (double(a[i]) + b[i]);
        ++n;
    }
    if (n == 0) return 0;
    mean /= double(n);
    const double offset = 0.01 * mean * mean;
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (!std::isfinite(a[i]) || !std::isfinite(b[i])) continue;
        const double m = 0.5 * (double(a[i]) + b[i]);
        const double d = double(a[i]) - b[i];
        const double denominator = m * m + offset;
        if (denominator > 0) sum += 0.5 * d * d / denominator;
    }
    return sum / double(n);
}

double HalvesRelMse(std::span<const float> half0, std::span<const float> half1) {
    if (half0.empty() || half1.empty()) return std::nan("");
    return 0.5 * PairRelMse(half0, half1);
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

}  // namespace nave
