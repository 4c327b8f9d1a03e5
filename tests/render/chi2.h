#pragma once
// Statistical test of a direction sampler against its pdf (Pearson's χ², as in pbrt-v4's
// bsdfs_test.cpp): histogram of sampled directions over a (θ, φ) grid vs. the pdf integrated over
// each cell. Test helper.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "src/core/vecmath.h"

namespace nave::testing {

/// Deterministic PCG32 (O'Neill 2014) so that the tests do not depend on the standard library's
/// engines.
class Pcg32 {
  public:
    explicit Pcg32(uint64_t seed) {
        state_ = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    }
    uint32_t NextU32() {
        uint64_t old = state_;
        state_ = old * 6364136223846793005ULL + 1442695040888963407ULL;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32 - rot) & 31));
    }
    /// Uniform in [0, 1).
    float NextFloat() { return std::min(float(NextU32()) * 0x1p-32f, 0x1.fffffep-1f); }

  private:
    uint64_t state_;
};

/// Regularised lower incomplete gamma function P(a, x) (series for x < a + 1, continued fraction
/// otherwise; e.g. Abramowitz & Stegun 6.5.29 and 6.5.31).
inline double GammaP(double a, double x) {
    if (x <= 0) return 0;
    double gln = std::lgamma(a);
    if (x < a + 1) {
        double sum = 1.0 / a, del = sum, ap = a;
        for (int n = 0; n < 1000; ++n) {
            ap += 1;
            del *= x / ap;
            sum += del;
            if (std::abs(del) < std::abs(sum) * 1e-15) break;
        }
        return sum * std::exp(-x + a * std::log(x) - gln);
    }
    // Lentz's continued fraction for Q(a, x).
    double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
    for (int i = 1; i < 1000; ++i) {
        double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        if (std::abs(d) < 1e-300) d = 1e-300;
        c = b + an / c;
        if (std::abs(c) < 1e-300) c = 1e-300;
        d = 1 / d;
        double del = d * c;
        h *= del;
        if (std::abs(del - 1) < 1e-15) break;
    }
    return 1.0 - std::exp(-x + a * std::log(x) - gln) * h;
}

struct Chi2Result {
    bool passed = false;
    double p_value = 0;
    std::string message;
};

/// `sample(u1, u2, u3)` returns a unit direction or nothing; `pdf(w)` its solid-angle density.
inline Chi2Result Chi2Test(const std::function<std::optional<Vec3f>(float, float, float)>& sample,
                           const std::function<float(const Vec3f&)>& pdf, uint64_t seed,
                           int num_samples = 200000, int theta_res = 10,
                           double significance = 0.01) {
    const int phi_res = 2 * theta_res;
    std::vector<double> observed(size_t(theta_res * phi_res), 0.0), expected(observed.size(), 0.0);
    Pcg32 rng(seed);
    for (int i = 0; i < num_samples; ++i) {
        float u1 = rng.NextFloat(), u2 = rng.NextFloat(), u3 = rng.NextFloat();
        std::optional<Vec3f> w = sample(u1, u2, u3);
        if (!w) continue;
        double theta = std::acos(std::clamp(double(w->z), -1.0, 1.0));
        double phi = std::atan2(double(w->y), double(w->x));
        if (phi < 0) phi += 2 * M_PI;
        int ti = std::clamp(int(theta / M_PI * theta_res), 0, theta_res - 1);
        int pi = std::clamp(int(phi / (2 * M_PI) * phi_res), 0, phi_res - 1);
        observed[size_t(ti) * size_t(phi_res) + size_t(pi)] += 1;
    }
    // Integrate the pdf over each cell (midpoint rule on a fine sub-grid), in solid angle sinθ dθ
    // dφ.
    const int sub = 16;
    const double dt = M_PI / theta_res, dp = 2 * M_PI / phi_res;
    for (int ti = 0; ti < theta_res; ++ti)
        for (int pi = 0; pi < phi_res; ++pi) {
            double sum = 0;
            for (int a = 0; a < sub; ++a)
                for (int b = 0; b < sub; ++b) {
                    double theta = (ti + (a + 0.5) / sub) * dt, phi = (pi + (b + 0.5) / sub) * dp;
                    Vec3f w(float(std::sin(theta) * std::cos(phi)),
                            float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
                    sum += pdf(w) * std::sin(theta);
                }
            expected[size_t(ti) * size_t(phi_res) + size_t(pi)] =
                sum * (dt / sub) * (dp / sub) * num_samples;
        }
    // Pool cells with small expected counts (Pearson's test needs >= 5 per cell).
    std::vector<size_t> order(observed.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    double pooled_obs = 0, pooled_exp = 0, chi2 = 0;
    int dof = 0;
    Chi2Result result;
    for (size_t idx : order) {
        if (expected[idx] == 0 && observed[idx] > 0) {
            result.message =
                "samples in a cell where the pdf is zero (cell " + std::to_string(idx) + ")";
            return result;
        }
        if (expected[idx] < 5) {
            pooled_obs += observed[idx];
            pooled_exp += expected[idx];
            continue;
        }
        double d = observed[idx] - expected[idx];
        chi2 += d * d / expected[idx];
        ++dof;
    }
    if (pooled_exp > 0 || pooled_obs > 0) {
        if (pooled_exp < 5 && pooled_obs > 10 + 3 * pooled_exp) {
            result.message = "too many samples where the pdf is tiny";
            return result;
        }
        if (pooled_exp > 0) {
            double d = pooled_obs - pooled_exp;
            chi2 += d * d / pooled_exp;
            ++dof;
        }
    }
    dof -= 1;
    if (dof <= 0) {
        result.message = "too few cells for the test";
        return result;
    }
    result.p_value = 1.0 - GammaP(dof / 2.0, chi2 / 2.0);
    result.passed = result.p_value > significance;
    result.message = "chi2 = " + std::to_string(chi2) + ", dof = " + std::to_string(dof) +
                     ", p = " + std::to_string(result.p_value);
    return result;
}

}  // namespace nave::testing
