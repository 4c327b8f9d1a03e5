#include "src/core/rgb_to_spectrum.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <string>

#include "src/core/check.h"
#include "src/core/illuminant.h"

namespace nave {

float SigmoidPolynomial::MaxValue() const {
    // S is increasing, so the maximum of s is at the maximum of the parabola over t in [0, 1]: an
    // end point or the vertex t = -c1 / (2 c0).
    float m = std::max(Evaluate(kLambdaMinNm), Evaluate(kLambdaMaxNm));
    if (c0 != 0.f) {
        float t = -c1 / (2.f * c0);
        if (t > 0.f && t < 1.f) m = std::max(m, Sigmoid((c0 * t + c1) * t + c2));
    }
    return m;
}

Spectrum SigmoidPolynomial::ToSpectrum() const {
    return Spectrum::FromFunction([this](double lambda_nm) { return Evaluate(float(lambda_nm)); });
}

namespace {

constexpr int kR = RgbToSpectrumTable::kResolution;

double Smoothstep(double x) { return x * x * (3.0 - 2.0 * x); }

// The solver's quadrature: the 1 nm CIE tables times the white illuminant W, normalised so that a
// reflectance of 1 has Y = 1 (CIE 15:2004 eq. 7.1-7.3, k = 1 / Σ W ȳ).
struct Quadrature {
    std::vector<double> t, wx, wy, wz;
    Vec3d white_xyz;
};

Quadrature MakeQuadrature(const Spectrum& illuminant) {
    // The 1 nm products x̄W, ȳW, z̄W are summed into 5 nm bins evaluated at the bin's centre: the
    // sigmoid is smooth on that scale (the round trip through the 1 nm tables in the tests checks
    // it), and the solve is five times faster.
    constexpr int kBinNm = 5;
    Quadrature q;
    double norm = 0.0;
    for (int i = 0; i < Spectrum::kNumSamples; ++i) norm += CieY().sample(i) * illuminant.sample(i);
    for (int start = 0; start < Spectrum::kNumSamples; start += kBinNm) {
        int end = std::min(start + kBinNm, Spectrum::kNumSamples);
        double wx = 0, wy = 0, wz = 0;
        for (int i = start; i < end; ++i) {
            double w = illuminant.sample(i) / norm;
            wx += CieX().sample(i) * w;
            wy += CieY().sample(i) * w;
            wz += CieZ().sample(i) * w;
        }
        q.t.push_back(0.5 * double(start + end - 1) / double(Spectrum::kNumSamples - 1));
        q.wx.push_back(wx);
        q.wy.push_back(wy);
        q.wz.push_back(wz);
        q.white_xyz.x += wx;
        q.white_xyz.y += wy;
        q.white_xyz.z += wz;
    }
    return q;
}

// CIELAB's f (CIE 15:2004 eq. 8.4-8.6) and its derivative, for the solver's Jacobian.
double LabFDerivative(double t) {
    constexpr double kD = 6.0 / 29.0;
    return t > kD * kD * kD ? 1.0 / (3.0 * std::cbrt(t * t)) : 1.0 / (3.0 * kD * kD);
}

struct Eval {
    Vec3d lab;
    Mat3d jacobian;  // ∂Lab / ∂(c0, c1, c2)
};

Eval Evaluate(const Quadrature& q, const std::array<double, 3>& c) {
    Vec3d xyz;
    Mat3d jx;  // ∂XYZ / ∂c
    for (size_t k = 0; k < q.t.size(); ++k) {
        double t = q.t[k];
        double x = (c[0] * t + c[1]) * t + c[2];
        double r = 1.0 / std::sqrt(1.0 + x * x);
        double s = 0.5 + 0.5 * x * r;
        // dS/dx = 1 / (2 (1 + x²)^{3/2}).
        double ds = 0.5 * r * r * r;
        double dc[3] = {ds * t * t, ds * t, ds};
        double w[3] = {q.wx[k], q.wy[k], q.wz[k]};
        for (int ch = 0; ch < 3; ++ch) {
            (ch == 0 ? xyz.x : ch == 1 ? xyz.y : xyz.z) += w[ch] * s;
            for (int j = 0; j < 3; ++j) jx.m[ch][j] += w[ch] * dc[j];
        }
    }
    Eval e;
    e.lab = XYZToLab(xyz, q.white_xyz);
    // L = 116 f(Y/Yn) - 16, a = 500 (f(X/Xn) - f(Y/Yn)), b = 200 (f(Y/Yn) - f(Z/Zn)).
    double fx = LabFDerivative(xyz.x / q.white_xyz.x) / q.white_xyz.x;
    double fy = LabFDerivative(xyz.y / q.white_xyz.y) / q.white_xyz.y;
    double fz = LabFDerivative(xyz.z / q.white_xyz.z) / q.white_xyz.z;
    Mat3d jl;
    jl.m = {
        {{0.0, 116.0 * fy, 0.0}, {500.0 * fx, -500.0 * fy, 0.0}, {0.0, 200.0 * fy, -200.0 * fz}}};
    e.jacobian = jl * jx;
    return e;
}

double Norm(const Vec3d& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

// Gauss-Newton (here Newton: three equations, three unknowns) on the CIELAB residual, from the
// warm start `c`, with step halving when a step does not reduce the residual. Returns the final
// ΔE*ab.
double Fit(const Quadrature& q, const Vec3d& target_lab, std::array<double, 3>& c) {
    Eval e = Evaluate(q, c);
    double err = Norm(e.lab - target_lab);
    for (int iter = 0; iter < 64 && err > 1e-4; ++iter) {
        const Mat3d& j = e.jacobian;
        double det = j(0, 0) * (j(1, 1) * j(2, 2) - j(1, 2) * j(2, 1)) -
                     j(0, 1) * (j(1, 0) * j(2, 2) - j(1, 2) * j(2, 0)) +
                     j(0, 2) * (j(1, 0) * j(2, 1) - j(1, 1) * j(2, 0));
        if (!(std::abs(det) > 1e-300)) break;
        Vec3d step = j.Inverse() * (e.lab - target_lab);
        double scale = 1.0;
        bool improved = false;
        for (int halving = 0; halving < 12; ++halving, scale *= 0.5) {
            std::array<double, 3> trial = {c[0] - scale * step.x, c[1] - scale * step.y,
                                           c[2] - scale * step.z};
            Eval te = Evaluate(q, trial);
            double terr = Norm(te.lab - target_lab);
            if (terr < err) {
                c = trial;
                e = te;
                err = terr;
                improved = true;
                break;
            }
        }
        if (!improved) break;
    }
    return err;
}

Spectrum WhiteIlluminant(const RgbColorSpace& space) {
    Spectrum w;
    Chromaticity d65 = IlluminantChromaticity(IlluminantD65());
    if (std::abs(space.white().x - d65.x) < 5e-4 && std::abs(space.white().y - d65.y) < 5e-4) {
        w = IlluminantD65();
    } else {
        // A CIE daylight of the white point's correlated colour temperature (ACES' white is the
        // ~6000 K daylight by construction, SMPTE ST 2065-1 Annex).
        w = Spectrum::CieIlluminantD(CctMcCamy(space.white()));
    }
    return w * float(1.0 / SpectrumToXYZ(w).y);
}

}  // namespace

RgbToSpectrumTable::RgbToSpectrumTable(const RgbColorSpace& space)
    : space_(&space), illuminant_(WhiteIlluminant(space)), coefficients_(size_t(3) * kR * kR * kR) {
    // z nodes: smoothstep(smoothstep(i / (R - 1))), denser near 0 and 1 (Jakob & Hanika 2019 §4).
    for (int i = 0; i < kR; ++i) z_nodes_[i] = float(Smoothstep(Smoothstep(double(i) / (kR - 1))));
    const Quadrature q = MakeQuadrature(illuminant_);
    const Vec3d white_xyz = q.white_xyz;
    std::array<double, 3> max_de{};
    auto solve_component = [&](int l) {
        for (int yi = 0; yi < kR; ++yi) {
            for (int xi = 0; xi < kR; ++xi) {
                double x = double(xi) / (kR - 1), y = double(yi) / (kR - 1);
                auto solve_at = [&](int zi, std::array<double, 3>& c) {
                    double z = z_nodes_[zi];
                    Vec3d rgb;
                    rgb[l] = z;
                    rgb[(l + 1) % 3] = x * z;
                    rgb[(l + 2) % 3] = y * z;
                    Vec3d target = XYZToLab(space.ToXyz(rgb), white_xyz);
                    double de = Fit(q, target, c);
                    // Black (z = 0) cannot be reached by a finite c; its node only anchors the
                    // interpolation towards dark colours and is not a quality measure.
                    if (zi > 0) max_de[l] = std::max(max_de[l], de);
                    coefficients_[((size_t(l) * kR + zi) * kR + yi) * kR + xi] = {
                        float(c[0]), float(c[1]), float(c[2])};
                };
                // Continuation (paper §4): start at a mid-dark node from the flat grey 0.5, walk
                // up to z = 1 and down to 0, each solve warm-started from its neighbour.
                const int start = kR / 5;
                std::array<double, 3> c = {0.0, 0.0, 0.0};
                for (int zi = start; zi < kR; ++zi) solve_at(zi, c);
                c = {double(coefficients_[((size_t(l) * kR + start) * kR + yi) * kR + xi][0]),
                     double(coefficients_[((size_t(l) * kR + start) * kR + yi) * kR + xi][1]),
                     double(coefficients_[((size_t(l) * kR + start) * kR + yi) * kR + xi][2])};
                for (int zi = start - 1; zi >= 0; --zi) solve_at(zi, c);
            }
        }
    };
    // The three components are independent.
    tbb::parallel_for(0, 3, solve_component);
    max_node_delta_e_ = std::max({max_de[0], max_de[1], max_de[2]});
}

const RgbToSpectrumTable& RgbToSpectrumTable::For(const RgbColorSpace& space) {
    static std::mutex mutex;
    static std::map<std::string, std::unique_ptr<RgbToSpectrumTable>>* tables =
        new std::map<std::string, std::unique_ptr<RgbToSpectrumTable>>();
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<RgbToSpectrumTable>& t = (*tables)[space.name()];
    if (!t) t = std::make_unique<RgbToSpectrumTable>(space);
    return *t;
}

SigmoidPolynomial RgbToSpectrumTable::Lookup(const Vec3f& rgb_in) const {
    Vec3f rgb(std::clamp(rgb_in.x, 0.f, 1.f), std::clamp(rgb_in.y, 0.f, 1.f),
              std::clamp(rgb_in.z, 0.f, 1.f));
    if (rgb.x == rgb.y && rgb.y == rgb.z) {
        // A grey is the constant S⁻¹(v) = (v - 1/2) / sqrt(v (1 - v)): exact, and ±inf at 1, 0.
        float v = rgb.x;
        if (v >= 1.f) return {0.f, 0.f, std::numeric_limits<float>::infinity()};
        if (v <= 0.f) return {0.f, 0.f, -std::numeric_limits<float>::infinity()};
        return {0.f, 0.f, (v - 0.5f) / std::sqrt(v * (1.f - v))};
    }
    int l = 0;
    if (rgb[1] > rgb[l]) l = 1;
    if (rgb[2] > rgb[l]) l = 2;
    float z = rgb[l];
    float x = rgb[(l + 1) % 3] / z * float(kR - 1);
    float y = rgb[(l + 2) % 3] / z * float(kR - 1);
    int xi = std::min(int(x), kR - 2), yi = std::min(int(y), kR - 2);
    float dx = x - float(xi), dy = y - float(yi);
    int zi = int(std::upper_bound(z_nodes_.begin(), z_nodes_.end(), z) - z_nodes_.begin()) - 1;
    zi = std::clamp(zi, 0, kR - 2);
    float dz = (z - z_nodes_[zi]) / (z_nodes_[zi + 1] - z_nodes_[zi]);
    std::array<float, 3> c{};
    for (int corner = 0; corner < 8; ++corner) {
        int ox = corner & 1, oy = (corner >> 1) & 1, oz = (corner >> 2) & 1;
        float w = (ox ? dx : 1.f - dx) * (oy ? dy : 1.f - dy) * (oz ? dz : 1.f - dz);
        const std::array<float, 3>& n =
            coefficients_[((size_t(l) * kR + zi + oz) * kR + yi + oy) * kR + xi + ox];
        for (int j = 0; j < 3; ++j) c[j] += w * n[j];
    }
    return {c[0], c[1], c[2]};
}

SigmoidPolynomial UpliftReflectance(const Vec3f& rgb, const RgbColorSpace& space) {
    return RgbToSpectrumTable::For(space).Lookup(rgb);
}

RgbEmission::RgbEmission(const Vec3f& rgb, const RgbColorSpace& space) {
    const RgbToSpectrumTable& table = RgbToSpectrumTable::For(space);
    illuminant_ = &table.illuminant();
    float m = std::max({rgb.x, rgb.y, rgb.z, 0.f});
    scale_ = 2.f * m;
    shape_ = scale_ > 0.f ? table.Lookup(Vec3f(rgb.x / scale_, rgb.y / scale_, rgb.z / scale_))
                          : SigmoidPolynomial{};
}

Spectrum RgbEmission::ToSpectrum() const {
    if (scale_ == 0.f) return Spectrum();
    return Spectrum::FromFunction([this](double lambda_nm) { return Evaluate(float(lambda_nm)); });
}

}  // namespace nave
