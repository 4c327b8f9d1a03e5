#include "src/core/color.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>

#include "src/core/spectrum_data.h"

namespace nave {

namespace {

struct Cmfs {
    Spectrum x, y, z;
    double y_integral = 0;
    Cmfs() {
        const SpectraTable& t = EmbeddedSpectraTable("cie_1931_2deg_cmf.csv");
        x = t.ToSpectrum(0);
        y = t.ToSpectrum(1);
        z = t.ToSpectrum(2);
        // The table is at 1 nm over exactly nave's range, so the 1 nm sum is the integral (CIE
        // 15:2004 §7.1 recommends summation at the table's interval).
        for (int i = 0; i < Spectrum::kNumSamples; ++i) y_integral += y.sample(i);
    }
};

const Cmfs& GetCmfs() {
    static const Cmfs cmfs;
    return cmfs;
}

}  // namespace

const Spectrum& CieX() { return GetCmfs().x; }
const Spectrum& CieY() { return GetCmfs().y; }
const Spectrum& CieZ() { return GetCmfs().z; }
double CieYIntegral() { return GetCmfs().y_integral; }

// ---- Mat3d

Mat3d Mat3d::Identity() { return Diagonal({1, 1, 1}); }

Mat3d Mat3d::Diagonal(const Vec3d& d) {
    Mat3d r;
    r.m[0][0] = d.x;
    r.m[1][1] = d.y;
    r.m[2][2] = d.z;
    return r;
}

Mat3d Mat3d::FromColumns(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    Mat3d r;
    for (int i = 0; i < 3; ++i) {
        r.m[i][0] = a[i];
        r.m[i][1] = b[i];
        r.m[i][2] = c[i];
    }
    return r;
}

Vec3d Mat3d::operator*(const Vec3d& v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

Mat3d Mat3d::operator*(const Mat3d& o) const {
    Mat3d r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.m[i][j] = m[i][0] * o.m[0][j] + m[i][1] * o.m[1][j] + m[i][2] * o.m[2][j];
    return r;
}

Mat3d Mat3d::Inverse() const {
    // Adjugate over determinant; 3x3 colour matrices are well conditioned.
    const auto& a = m;
    double c00 = a[1][1] * a[2][2] - a[1][2] * a[2][1];
    double c01 = a[1][2] * a[2][0] - a[1][0] * a[2][2];
    double c02 = a[1][0] * a[2][1] - a[1][1] * a[2][0];
    double det = a[0][0] * c00 + a[0][1] * c01 + a[0][2] * c02;
    NAVE_CHECK(det != 0.0 && std::isfinite(det)) << "singular 3x3 matrix " << *this;
    double inv = 1.0 / det;
    Mat3d r;
    r.m[0][0] = c00 * inv;
    r.m[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) * inv;
    r.m[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) * inv;
    r.m[1][0] = c01 * inv;
    r.m[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) * inv;
    r.m[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) * inv;
    r.m[2][0] = c02 * inv;
    r.m[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) * inv;
    r.m[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) * inv;
    return r;
}

std::ostream& operator<<(std::ostream& os, const Mat3d& m) {
    os << "[";
    for (int i = 0; i < 3; ++i)
        os << (i ? "; " : "") << m.m[i][0] << ", " << m.m[i][1] << ", " << m.m[i][2];
    return os << "]";
}

// ---- XYZ

Chromaticity XYZToChromaticity(const Vec3d& xyz) {
    double sum = xyz.x + xyz.y + xyz.z;
    if (sum == 0.0) return {0, 0};
    return {xyz.x / sum, xyz.y / sum};
}

Vec3d ChromaticityToXYZ(const Chromaticity& xy, double Y) {
    if (xy.y == 0.0) return {0, 0, 0};
    return {xy.x * Y / xy.y, Y, (1.0 - xy.x - xy.y) * Y / xy.y};
}

Vec3d SpectrumToXYZ(const Spectrum& s) {
    const Cmfs& c = GetCmfs();
    Vec3d xyz;
    for (int i = 0; i < Spectrum::kNumSamples; ++i) {
        double v = s.sample(i);
        xyz += Vec3d(c.x.sample(i) * v, c.y.sample(i) * v, c.z.sample(i) * v);
    }
    return xyz / c.y_integral;
}

Vec3d ReflectanceToXYZ(const Spectrum& reflectance, const Spectrum& illuminant) {
    const Cmfs& c = GetCmfs();
    Vec3d xyz;
    double k = 0;
    for (int i = 0; i < Spectrum::kNumSamples; ++i) {
        double s = illuminant.sample(i);
        double sr = s * reflectance.sample(i);
        xyz += Vec3d(c.x.sample(i) * sr, c.y.sample(i) * sr, c.z.sample(i) * sr);
        k += c.y.sample(i) * s;
    }
    NAVE_CHECK(k > 0) << "illuminant has no luminance";
    return xyz / k;
}

Vec3d SampledToXYZ(const SampledSpectrum& L, const SampledWavelengths& lambda) {
    const Cmfs& c = GetCmfs();
    SampledSpectrum pdf = lambda.Pdf();
    Vec3d xyz;
    for (int i = 0; i < kNumWavelengths; ++i) {
        if (pdf[i] == 0.f) continue;
        double w = double(L[i]) / double(pdf[i]);
        float l = lambda.lambda_nm(i);
        xyz += Vec3d(c.x.Evaluate(l) * w, c.y.Evaluate(l) * w, c.z.Evaluate(l) * w);
    }
    return xyz / (double(kNumWavelengths) * c.y_integral);
}

// ---- RGB colour spaces

RgbColorSpace::RgbColorSpace(std::string name, Chromaticity r, Chromaticity g, Chromaticity b,
                             Chromaticity white)
    : name_(std::move(name)), r_(r), g_(g), b_(b), white_(white) {
    // SMPTE RP 177-1993 §3.3: the columns are the primaries' XYZ (Y = 1) scaled so that RGB (1,1,1)
    // maps to the white point with Y = 1.
    Mat3d p = Mat3d::FromColumns(ChromaticityToXYZ(r), ChromaticityToXYZ(g), ChromaticityToXYZ(b));
    Vec3d scale = p.Inverse() * ChromaticityToXYZ(white);
    rgb_to_xyz_ = p * Mat3d::Diagonal(scale);
    xyz_to_rgb_ = rgb_to_xyz_.Inverse();
}

const RgbColorSpace& RgbColorSpace::Srgb() {
    // IEC 61966-2-1:1999 / ITU-R BT.709-6 Table 1: primaries and D65 white.
    static const RgbColorSpace s("sRGB", {0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06},
                                 {0.3127, 0.3290});
    return s;
}

const RgbColorSpace& RgbColorSpace::Rec2020() {
    // ITU-R BT.2020-2 Table 3.
    static const RgbColorSpace s("Rec.2020", {0.708, 0.292}, {0.170, 0.797}, {0.131, 0.046},
                                 {0.3127, 0.3290});
    return s;
}

const RgbColorSpace& RgbColorSpace::AcesCg() {
    // Academy S-2014-004 (ACEScg): AP1 primaries, ACES white point (SMPTE ST 2065-1).
    static const RgbColorSpace s("ACEScg", {0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044},
                                 {0.32168, 0.33767});
    return s;
}

StatusOr<const RgbColorSpace*> RgbColorSpace::Named(std::string_view name) {
    std::string lower;
    for (char ch : name) lower += char(std::tolower(static_cast<unsigned char>(ch)));
    if (lower == "srgb" || lower == "linear-srgb" || lower == "rec709") return &Srgb();
    if (lower == "rec2020" || lower == "rec.2020" || lower == "bt2020") return &Rec2020();
    if (lower == "acescg") return &AcesCg();
    return NotFoundError("unknown colour space '{}' (known: srgb, rec2020, acescg)", name);
}

// ---- Chromatic adaptation

namespace {

Mat3d ConeMatrix(AdaptationMethod method) {
    Mat3d m;
    switch (method) {
        case AdaptationMethod::kBradford:
            // Lam (1985); as in ICC.1:2010 Annex E and Lindbloom's tables.
            m.m = {
                {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}}};
            break;
        case AdaptationMethod::kVonKries:
            // Hunt-Pointer-Estévez fundamentals normalised to D65 (Fairchild, Color Appearance
            // Models, 3rd ed., eq. 9.1).
            m.m = {
                {{0.40024, 0.70760, -0.08081}, {-0.22630, 1.16532, 0.04570}, {0.0, 0.0, 0.91822}}};
            break;
        case AdaptationMethod::kXyzScaling:
            m = Mat3d::Identity();
            break;
        case AdaptationMethod::kCat02:
            // CIE 159:2004, "A colour appearance model for colour management systems: CIECAM02",
            // eq. 7 (M_CAT02; each row sums to 1: equal-energy white gives equal responses).
            m.m = {
                {{0.7328, 0.4296, -0.1624}, {-0.7036, 1.6975, 0.0061}, {0.0030, 0.0136, 0.9834}}};
            break;
        case AdaptationMethod::kCat16:
            // Li, Li, Wang, Zu, Luo, Cui, Melgosa, Brill & Pointer 2017, "Comprehensive color
            // solutions: CAM16, CAT16, and CAM16-UCS", Color Res. Appl. 42(6), eq. 1 (M16).
            m.m = {{{0.401288, 0.650173, -0.051461},
                    {-0.250268, 1.204414, 0.045854},
                    {-0.002079, 0.048952, 0.953127}}};
            break;
    }
    return m;
}

}  // namespace

std::optional<AdaptationMethod> ParseAdaptationMethod(std::string_view name) {
    if (name == "bradford") return AdaptationMethod::kBradford;
    if (name == "von_kries") return AdaptationMethod::kVonKries;
    if (name == "xyz_scaling") return AdaptationMethod::kXyzScaling;
    if (name == "cat02") return AdaptationMethod::kCat02;
    if (name == "cat16") return AdaptationMethod::kCat16;
    return std::nullopt;
}

Mat3d ChromaticAdaptationMatrix(const Chromaticity& src, const Chromaticity& dst,
                                AdaptationMethod method) {
    // Von Kries-type transform: M⁻¹ diag(ρD/ρS, γD/γS, βD/βS) M (Fairchild eq. 9.2).
    Mat3d m = ConeMatrix(method);
    Vec3d s = m * ChromaticityToXYZ(src);
    Vec3d d = m * ChromaticityToXYZ(dst);
    return m.Inverse() * Mat3d::Diagonal({d.x / s.x, d.y / s.y, d.z / s.z}) * m;
}

Mat3d WhiteBalancedXyzToRgb(const RgbColorSpace& space, const Chromaticity& scene_white,
                            AdaptationMethod method) {
    return space.xyz_to_rgb() * ChromaticAdaptationMatrix(scene_white, space.white(), method);
}

// ---- Output

double SrgbEncode(double linear) {
    // IEC 61966-2-1:1999 §5.2, eq. (5).
    if (linear <= 0.0031308) return 12.92 * linear;
    return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double SrgbDecode(double encoded) {
    if (encoded <= 0.04045) return encoded / 12.92;
    return std::pow((encoded + 0.055) / 1.055, 2.4);
}

Vec3d ApplyExposure(const Vec3d& rgb, double ev) { return rgb * std::exp2(ev); }

std::array<uint8_t, 3> LinearSrgbTo8Bit(const Vec3d& linear_rgb) {
    std::array<uint8_t, 3> out{};
    for (int i = 0; i < 3; ++i) {
        double v = std::isfinite(linear_rgb[i]) ? std::clamp(linear_rgb[i], 0.0, 1.0) : 0.0;
        out[i] = uint8_t(std::lround(SrgbEncode(v) * 255.0));
    }
    return out;
}

Vec3d XYZToLab(const Vec3d& xyz, const Vec3d& white_xyz) {
    // CIE 15:2004 eqs. (8.3)-(8.8), in the form with ε = (6/29)³ that is continuous at the joint.
    auto f = [](double t) {
        constexpr double kD = 6.0 / 29.0;
        return t > kD * kD * kD ? std::cbrt(t) : t / (3.0 * kD * kD) + 4.0 / 29.0;
    };
    double fx = f(xyz.x / white_xyz.x), fy = f(xyz.y / white_xyz.y), fz = f(xyz.z / white_xyz.z);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

double DeltaE76(const Vec3d& lab1, const Vec3d& lab2) { return Length(lab1 - lab2); }

double CctMcCamy(const Chromaticity& xy) {
    // McCamy (1992) eq. (3): n = (x - xe) / (ye - y), epicentre (0.3320, 0.1858).
    double n = (xy.x - 0.3320) / (0.1858 - xy.y);
    return 449.0 * n * n * n + 3525.0 * n * n + 6823.3 * n + 5520.33;
}

double CctRobertson(const Chromaticity& xy) {
    // Isotemperature lines: reciprocal temperature (MK⁻¹), u, v on the Planckian locus, slope t
    // (Wyszecki & Stiles 1982, Table 1(3.11)).
    struct Line {
        double mired, u, v, t;
    };
    static constexpr Line kLines[] = {
        {0, 0.18006, 0.26352, -0.24341},   {10, 0.18066, 0.26589, -0.25479},
        {20, 0.18133, 0.26846, -0.26876},  {30, 0.18208, 0.27119, -0.28539},
        {40, 0.18293, 0.27407, -0.30470},  {50, 0.18388, 0.27709, -0.32675},
        {60, 0.18494, 0.28021, -0.35156},  {70, 0.18611, 0.28342, -0.37915},
        {80, 0.18740, 0.28668, -0.40955},  {90, 0.18880, 0.28997, -0.44278},
        {100, 0.19032, 0.29326, -0.47888}, {125, 0.19462, 0.30141, -0.58204},
        {150, 0.19962, 0.30921, -0.70471}, {175, 0.20525, 0.31647, -0.84901},
        {200, 0.21142, 0.32312, -1.0182},  {225, 0.21807, 0.32909, -1.2168},
        {250, 0.22511, 0.33439, -1.4512},  {275, 0.23247, 0.33904, -1.7298},
        {300, 0.24010, 0.34308, -2.0637},  {325, 0.24792, 0.34655, -2.4681},
        {350, 0.25591, 0.34951, -2.9641},  {375, 0.26400, 0.35200, -3.5814},
        {400, 0.27218, 0.35407, -4.3633},  {425, 0.28039, 0.35577, -5.3762},
        {450, 0.28863, 0.35714, -6.7262},  {475, 0.29685, 0.35823, -8.5955},
        {500, 0.30505, 0.35907, -11.324},  {525, 0.31320, 0.35968, -15.628},
        {550, 0.32129, 0.36011, -23.325},  {575, 0.32931, 0.36038, -40.770},
        {600, 0.33724, 0.36051, -116.45},
    };
    // CIE 1960 UCS: u = 4x / (-2x + 12y + 3), v = 6y / (-2x + 12y + 3).
    double den = -2.0 * xy.x + 12.0 * xy.y + 3.0;
    if (den == 0.0) return NAN;
    double u = 4.0 * xy.x / den, v = 6.0 * xy.y / den;
    // Signed distance of (u, v) from each isotemperature line; the CCT lies between the two lines
    // where it changes sign (Robertson 1968 eq. 3).
    double prev_d = 0;
    for (size_t i = 0; i < std::size(kLines); ++i) {
        const Line& l = kLines[i];
        double d = ((v - l.v) - l.t * (u - l.u)) / std::sqrt(1.0 + l.t * l.t);
        if (i > 0 && ((prev_d < 0) != (d < 0) || d == 0)) {
            const Line& p = kLines[i - 1];
            double f = prev_d / (prev_d - d);
            double mired = p.mired + f * (l.mired - p.mired);
            return mired > 0 ? 1e6 / mired : INFINITY;
        }
        prev_d = d;
    }
    return NAN;
}

}  // namespace nave
