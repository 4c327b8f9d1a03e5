#include "src/render/scene/sun/spa.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>

#include "src/render/scene/sun/spa_tables.h"

namespace nave {

namespace {

constexpr double kPi = std::numbers::pi;
double Rad(double deg) { return deg * kPi / 180.0; }
double Deg(double rad) { return rad * 180.0 / kPi; }
/// Limits an angle to [0, 360) (SPA eq. 12 step 3.2.6).
double LimitDegrees(double deg) {
    double d = std::fmod(deg, 360.0);
    return d < 0 ? d + 360.0 : d;
}

// ---- ISO 8601 ----

bool ParseInt(std::string_view s, int* v) {
    if (s.empty()) return false;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), *v);
    return ec == std::errc() && p == s.data() + s.size();
}

int DaysInMonth(int year, int month) {
    static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (month != 2) return kDays[month - 1];
    // Gregorian leap rule from 1583 on, Julian before (every 4th year), matching JulianDay.
    bool leap =
        year > 1582 ? (year % 4 == 0 && (year % 100 != 0 || year % 400 == 0)) : (year % 4 == 0);
    return leap ? 29 : 28;
}

}  // namespace

StatusOr<CivilTime> ParseIso8601(std::string_view text) {
    auto bad = [&](std::string_view why) {
        return InvalidArgumentError(
            "time '{}': {} (expected ISO 8601 like 2003-10-17T12:30:30-07:00 or 2024-06-21T12:00Z)",
            text, why);
    };
    std::string_view s = text;
    CivilTime t;
    // Date: [-]YYYY-MM-DD (a leading '-' for years before 1 BC in astronomical numbering).
    bool negative = !s.empty() && s[0] == '-';
    if (negative) s.remove_prefix(1);
    size_t dash1 = s.find('-');
    if (dash1 == std::string_view::npos || dash1 < 4) return bad("no YYYY-MM-DD date");
    if (!ParseInt(s.substr(0, dash1), &t.year)) return bad("bad year");
    if (negative) t.year = -t.year;
    s.remove_prefix(dash1 + 1);
    if (s.size() < 5 || s[2] != '-') return bad("no YYYY-MM-DD date");
    if (!ParseInt(s.substr(0, 2), &t.month) || !ParseInt(s.substr(3, 2), &t.day))
        return bad("bad month or day");
    s.remove_prefix(5);
    if (t.month < 1 || t.month > 12) return bad("month out of range 1-12");
    if (t.day < 1 || t.day > DaysInMonth(t.year, t.month))
        return bad("day out of range for the month");
    if (t.year == 1582 && t.month == 10 && t.day > 4 && t.day < 15)
        return bad("1582-10-05..14 do not exist (Julian to Gregorian change)");
    if (s.empty() || (s[0] != 'T' && s[0] != 't' && s[0] != ' ')) return bad("no time of day");
    s.remove_prefix(1);
    // Time: hh:mm[:ss[.fff]]
    if (s.size() < 5 || s[2] != ':') return bad("bad time of day (hh:mm[:ss])");
    if (!ParseInt(s.substr(0, 2), &t.hour) || !ParseInt(s.substr(3, 2), &t.minute))
        return bad("bad hour or minute");
    s.remove_prefix(5);
    if (!s.empty() && s[0] == ':') {
        s.remove_prefix(1);
        size_t end = 0;
        while (end < s.size() &&
               (std::isdigit(static_cast<unsigned char>(s[end])) || s[end] == '.'))
            ++end;
        auto [p, ec] = std::from_chars(s.data(), s.data() + end, t.second);
        if (ec != std::errc() || p != s.data() + end || end == 0) return bad("bad seconds");
        s.remove_prefix(end);
    }
    if (t.hour > 24 || t.minute > 59 || t.second < 0 || t.second >= 61)
        return bad("time of day out of range");
    // Zone.
    if (s.empty())
        return InvalidArgumentError(
            "time '{}' has no time zone (add Z for UTC or an offset such as -07:00)", text);
    if (s == "Z" || s == "z") {
        t.utc_offset_hours = 0;
    } else if (s[0] == '+' || s[0] == '-') {
        int sign = s[0] == '-' ? -1 : 1;
        s.remove_prefix(1);
        int hh = 0, mm = 0;
        if (s.size() == 5 && s[2] == ':') {
            if (!ParseInt(s.substr(0, 2), &hh) || !ParseInt(s.substr(3, 2), &mm))
                return bad("bad zone");
        } else if (s.size() == 4) {
            if (!ParseInt(s.substr(0, 2), &hh) || !ParseInt(s.substr(2, 2), &mm))
                return bad("bad zone");
        } else if (s.size() == 2) {
            if (!ParseInt(s, &hh)) return bad("bad zone");
        } else {
            return bad("bad zone (Z, ±hh, ±hhmm or ±hh:mm)");
        }
        if (hh > 14 || mm > 59) return bad("zone offset out of range");
        t.utc_offset_hours = sign * (hh + mm / 60.0);
    } else {
        return bad("unexpected text after the time");
    }
    return t;
}

std::string FormatIso8601(const CivilTime& t) {
    int off_min = int(std::lround(t.utc_offset_hours * 60));
    std::string zone = off_min == 0 ? "Z"
                                    : fmt::format("{}{:02d}:{:02d}", off_min < 0 ? '-' : '+',
                                                  std::abs(off_min) / 60, std::abs(off_min) % 60);
    return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:06.3f}{}", t.year, t.month, t.day,
                       t.hour, t.minute, t.second, zone);
}

double EstimateDeltaT(double decimal_year) {
    // Espenak & Meeus (2006) §2.6, one polynomial per period, in their y.
    const double y = decimal_year;
    auto long_term = [](double year) {
        double u = (year - 1820.0) / 100.0;
        return -20.0 + 32.0 * u * u;
    };
    if (y < -500) return long_term(y);
    if (y < 500) {
        double u = y / 100.0;
        return 10583.6 +
               u * (-1014.41 +
                    u * (33.78311 + u * (-5.952053 +
                                         u * (-0.1798452 + u * (0.022174192 + u * 0.0090316521)))));
    }
    if (y < 1600) {
        double u = (y - 1000.0) / 100.0;
        return 1574.2 +
               u * (-556.01 +
                    u * (71.23472 + u * (0.319781 + u * (-0.8503463 +
                                                         u * (-0.005050998 + u * 0.0083572073)))));
    }
    if (y < 1700) {
        double t = y - 1600.0;
        return 120.0 - 0.9808 * t - 0.01532 * t * t + t * t * t / 7129.0;
    }
    if (y < 1800) {
        double t = y - 1700.0;
        return 8.83 + t * (0.1603 + t * (-0.0059285 + t * (0.00013336 - t / 1174000.0)));
    }
    if (y < 1860) {
        double t = y - 1800.0;
        return 13.72 +
               t * (-0.332447 +
                    t * (0.0068612 +
                         t * (0.0041116 +
                              t * (-0.00037436 + t * (0.0000121272 +
                                                      t * (-0.0000001699 + t * 0.000000000875))))));
    }
    if (y < 1900) {
        double t = y - 1860.0;
        return 7.62 + t * (0.5737 +
                           t * (-0.251754 + t * (0.01680668 + t * (-0.0004473624 + t / 233174.0))));
    }
    if (y < 1920) {
        double t = y - 1900.0;
        return -2.79 + t * (1.494119 + t * (-0.0598939 + t * (0.0061966 - t * 0.000197)));
    }
    if (y < 1941) {
        double t = y - 1920.0;
        return 21.20 + t * (0.84493 + t * (-0.076100 + t * 0.0020936));
    }
    if (y < 1961) {
        double t = y - 1950.0;
        return 29.07 + 0.407 * t - t * t / 233.0 + t * t * t / 2547.0;
    }
    if (y < 1986) {
        double t = y - 1975.0;
        return 45.45 + 1.067 * t - t * t / 260.0 - t * t * t / 718.0;
    }
    if (y < 2005) {
        double t = y - 2000.0;
        return 63.86 + t * (0.3345 + t * (-0.060374 +
                                          t * (0.0017275 + t * (0.000651814 + t * 0.00002373599))));
    }
    if (y < 2050) {
        double t = y - 2000.0;
        return 62.92 + 0.32217 * t + 0.005589 * t * t;
    }
    if (y < 2150) return long_term(y) - 0.5628 * (2150.0 - y);
    return long_term(y);
}

double JulianDay(int year, int month, double day) {
    // Reda & Andreas eq. (4): Meeus' algorithm; B = 0 for the Julian calendar.
    if (month < 3) {
        year -= 1;
        month += 12;
    }
    double jd =
        std::floor(365.25 * (year + 4716.0)) + std::floor(30.6001 * (month + 1)) + day - 1524.5;
    if (jd > 2299160.0) {  // 1582-10-15 and later: Gregorian
        double a = std::floor(year / 100.0);
        jd += 2.0 - a + std::floor(a / 4.0);
    }
    return jd;
}

namespace {

double EvaluateSeries(const spa::TermSeries* series, int count, double jme) {
    // Eq. (9)-(10): L = (L0 + L1 JME + L2 JME² + ...) / 1e8 with Li = Σ A cos(B + C JME).
    double sum = 0, power = 1;
    for (int i = 0; i < count; ++i) {
        double li = 0;
        for (int k = 0; k < series[i].count; ++k) {
            const spa::PeriodicTerm& t = series[i].terms[k];
            li += t.a * std::cos(t.b + t.c * jme);
        }
        sum += li * power;
        power *= jme;
    }
    return sum / 1e8;
}

}  // namespace

StatusOr<SpaResult> ComputeSolarPosition(const SpaInput& in) {
    const CivilTime& t = in.time;
    if (t.year < -2000 || t.year > 6000)
        return InvalidArgumentError("year {} out of the SPA's range [-2000, 6000]", t.year);
    if (t.month < 1 || t.month > 12)
        return InvalidArgumentError("month {} out of range [1, 12]", t.month);
    if (t.day < 1 || t.day > 31) return InvalidArgumentError("day {} out of range [1, 31]", t.day);
    if (t.hour < 0 || t.hour > 24 || t.minute < 0 || t.minute > 59 || t.second < 0 ||
        t.second >= 61)
        return InvalidArgumentError("time {:02d}:{:02d}:{} out of range", t.hour, t.minute,
                                    t.second);
    if (std::abs(t.utc_offset_hours) > 18)
        return InvalidArgumentError("UTC offset {} h out of range [-18, 18]", t.utc_offset_hours);
    if (!(std::abs(in.latitude_deg) <= 90))
        return InvalidArgumentError("latitude {}° out of range [-90, 90]", in.latitude_deg);
    if (!(std::abs(in.longitude_deg) <= 180))
        return InvalidArgumentError("longitude {}° out of range [-180, 180]", in.longitude_deg);
    if (!(in.elevation_m >= -6500000))
        return InvalidArgumentError("elevation {} m below the centre of the Earth", in.elevation_m);
    if (!(in.pressure_hpa >= 0 && in.pressure_hpa <= 5000))
        return InvalidArgumentError("pressure {} hPa out of range [0, 5000]", in.pressure_hpa);
    if (!(in.temperature_c > -273.15 && in.temperature_c <= 6000))
        return InvalidArgumentError("temperature {} °C out of range (-273.15, 6000]",
                                    in.temperature_c);
    if (!(std::abs(in.delta_t_s) <= 8000))
        return InvalidArgumentError("delta T {} s out of range [-8000, 8000]", in.delta_t_s);

    SpaResult r;
    // 3.1 Julian day from UT = local time - offset.
    double day_fraction =
        (t.hour + t.minute / 60.0 + t.second / 3600.0 - t.utc_offset_hours) / 24.0;
    r.jd = JulianDay(t.year, t.month, t.day + day_fraction);
    r.jde = r.jd + in.delta_t_s / 86400.0;  // eq. (5)
    r.jc = (r.jd - 2451545.0) / 36525.0;    // eq. (6)
    r.jce = (r.jde - 2451545.0) / 36525.0;  // eq. (7)
    r.jme = r.jce / 10.0;                   // eq. (8)

    // 3.2 Earth heliocentric longitude, latitude, radius.
    r.l_deg = LimitDegrees(Deg(EvaluateSeries(spa::kL, 6, r.jme)));
    r.b_deg = Deg(EvaluateSeries(spa::kB, 2, r.jme));
    r.r_au = EvaluateSeries(spa::kR, 5, r.jme);

    // 3.3 Geocentric longitude and latitude (eq. 13-14).
    double theta = LimitDegrees(r.l_deg + 180.0);
    double beta = -r.b_deg;

    // 3.4 Nutation (eq. 15-23).
    double jce = r.jce, jce2 = jce * jce, jce3 = jce2 * jce;
    double x[5] = {
        297.85036 + 445267.111480 * jce - 0.0019142 * jce2 + jce3 / 189474.0,
        357.52772 + 35999.050340 * jce - 0.0001603 * jce2 - jce3 / 300000.0,
        134.96298 + 477198.867398 * jce + 0.0086972 * jce2 + jce3 / 56250.0,
        93.27191 + 483202.017538 * jce - 0.0036825 * jce2 + jce3 / 327270.0,
        125.04452 - 1934.136261 * jce + 0.0020708 * jce2 + jce3 / 450000.0,
    };
    double dpsi = 0, deps = 0;
    for (const spa::NutationTerm& n : spa::kNutation) {
        double arg = 0;
        for (int j = 0; j < 5; ++j) arg += x[j] * n.y[j];
        arg = Rad(arg);
        dpsi += (n.a + n.b * jce) * std::sin(arg);
        deps += (n.c + n.d * jce) * std::cos(arg);
    }
    r.delta_psi_deg = dpsi / 36000000.0;
    r.delta_epsilon_deg = deps / 36000000.0;

    // 3.5 True obliquity of the ecliptic (eq. 24-25).
    double u = r.jme / 10.0;
    double eps0 =
        84381.448 +
        u * (-4680.93 +
             u * (-1.55 +
                  u * (1999.25 +
                       u * (-51.38 +
                            u * (-249.67 +
                                 u * (-39.05 +
                                      u * (7.12 + u * (27.87 + u * (5.79 + u * 2.45)))))))));
    r.epsilon_deg = eps0 / 3600.0 + r.delta_epsilon_deg;

    // 3.6-3.7 Aberration and apparent sun longitude (eq. 26-27).
    double dtau = -20.4898 / (3600.0 * r.r_au);
    r.lambda_deg = theta + r.delta_psi_deg + dtau;

    // 3.8 Apparent sidereal time at Greenwich (eq. 28-30).
    double nu0 = LimitDegrees(280.46061837 + 360.98564736629 * (r.jd - 2451545.0) +
                              r.jc * r.jc * (0.000387933 - r.jc / 38710000.0));
    r.nu_deg = nu0 + r.delta_psi_deg * std::cos(Rad(r.epsilon_deg));

    // 3.9-3.10 Geocentric right ascension and declination (eq. 31-32).
    double lam = Rad(r.lambda_deg), eps = Rad(r.epsilon_deg), bet = Rad(beta);
    r.alpha_deg = LimitDegrees(Deg(
        std::atan2(std::sin(lam) * std::cos(eps) - std::tan(bet) * std::sin(eps), std::cos(lam))));
    r.delta_deg = Deg(
        std::asin(std::sin(bet) * std::cos(eps) + std::cos(bet) * std::sin(eps) * std::sin(lam)));

    // 3.11 Observer local hour angle (eq. 33).
    r.h_deg = LimitDegrees(r.nu_deg + in.longitude_deg - r.alpha_deg);

    // 3.12 Topocentric right ascension (eq. 34-39): parallax of the observer's position.
    double xi = Rad(8.794 / (3600.0 * r.r_au));
    double phi = Rad(in.latitude_deg);
    double uu = std::atan(0.99664719 * std::tan(phi));
    double xx = std::cos(uu) + in.elevation_m / 6378140.0 * std::cos(phi);
    double yy = 0.99664719 * std::sin(uu) + in.elevation_m / 6378140.0 * std::sin(phi);
    double h = Rad(r.h_deg), delta = Rad(r.delta_deg);
    double dalpha = std::atan2(-xx * std::sin(xi) * std::sin(h),
                               std::cos(delta) - xx * std::sin(xi) * std::cos(h));
    r.alpha_prime_deg = r.alpha_deg + Deg(dalpha);
    double delta_p = std::atan2((std::sin(delta) - yy * std::sin(xi)) * std::cos(dalpha),
                                std::cos(delta) - xx * std::sin(xi) * std::cos(h));
    r.delta_prime_deg = Deg(delta_p);
    r.h_prime_deg = r.h_deg - Deg(dalpha);  // eq. (40)

    // 3.14 Topocentric zenith angle (eq. 41-44) with refraction (Bennett-type formula, eq. 42).
    double hp = Rad(r.h_prime_deg);
    r.e0_deg = Deg(std::asin(std::sin(phi) * std::sin(delta_p) +
                             std::cos(phi) * std::cos(delta_p) * std::cos(hp)));
    constexpr double kSunRadiusDeg = 0.26667;
    if (r.e0_deg >= -1.0 * (kSunRadiusDeg + in.atmos_refract_deg)) {
        r.refraction_deg = (in.pressure_hpa / 1010.0) * (283.0 / (273.0 + in.temperature_c)) *
                           1.02 / (60.0 * std::tan(Rad(r.e0_deg + 10.3 / (r.e0_deg + 5.11))));
    }
    r.elevation_deg = r.e0_deg + r.refraction_deg;
    r.zenith_deg = 90.0 - r.elevation_deg;

    // 3.15 Topocentric azimuth (eq. 45-46): astronomers' Γ from south, then from north eastward.
    double gamma = Deg(
        std::atan2(std::sin(hp), std::cos(hp) * std::sin(phi) - std::tan(delta_p) * std::cos(phi)));
    r.azimuth_deg = LimitDegrees(gamma + 180.0);
    return r;
}

}  // namespace nave
