#pragma once
// Solar position by the NREL Solar Position Algorithm (SPA): Reda & Andreas, "Solar position
// algorithm for solar radiation applications", Solar Energy 76(5) 577-589 (2004), corrigendum 81(6)
// 838 (2007); NREL/TP-560-34302 rev. 2008. Uncertainty ±0.0003° for years -2000 to 6000.
//
// Calendar: dates from 1582-10-15 on are Gregorian, earlier dates are Julian (the paper's eq. 4
// with B = 0), as astronomers count; there is no year 0 problem because years are astronomical (1
// BC = year 0).

#include <string>
#include <string_view>

#include "src/core/status.h"

namespace nave {

/// A civil date and time with its offset from UTC, e.g. 2003-10-17 12:30:30 at UTC-7.
struct CivilTime {
    int year = 2000, month = 1, day = 1;
    int hour = 0, minute = 0;
    double second = 0;
    /// Local time minus UTC, in hours (e.g. -7 for MST, +1 for CET). Required: nave never guesses a
    /// zone.
    double utc_offset_hours = 0;
};

/// Parses ISO 8601 "YYYY-MM-DDThh:mm[:ss[.fff]](Z|±hh[:mm])" (a space may replace the T). A time
/// without a zone is refused (InvalidArgument): "2003-10-17T12:30:30 has no time zone (add Z or
/// ±hh:mm)".
StatusOr<CivilTime> ParseIso8601(std::string_view text);
/// "2003-10-17T12:30:30-07:00".
std::string FormatIso8601(const CivilTime& t);

/// An estimate of ΔT = TT - UT (seconds) for a decimal year, from the polynomial expressions of
/// Espenak & Meeus, "Five Millennium Canon of Solar Eclipses: -1999 to +3000", NASA/TP-2006-214141,
/// §2.6 (after Morrison & Stephenson 2004). About 1570 s in 1000, 63.8 s in 2000; uncertain by
/// minutes in antiquity.
double EstimateDeltaT(double decimal_year);
/// The decimal year of a civil date (mid-month convention of Espenak & Meeus: y = year + (month -
/// 0.5)/12).
inline double DecimalYear(const CivilTime& t) { return t.year + (t.month - 0.5) / 12.0; }

/// Julian Day of a UT instant (Reda & Andreas eq. 4; Gregorian from 1582-10-15, Julian before).
double JulianDay(int year, int month, double day_with_fraction);

/// Inputs of the SPA.
struct SpaInput {
    CivilTime time;
    /// ΔT = TT - UT1 in seconds (≈ 69 s in 2020; see IERS Bulletin A or Espenak & Meeus
    /// polynomials).
    double delta_t_s = 69.0;
    double latitude_deg = 0;        ///< geodetic, north positive, [-90, 90]
    double longitude_deg = 0;       ///< east positive, [-180, 180]
    double elevation_m = 0;         ///< above sea level
    double pressure_hpa = 1013.25;  ///< annual mean local pressure, for refraction
    double temperature_c = 15;      ///< annual mean local temperature, for refraction
    /// Refraction at sunrise/sunset (°); refraction is applied only while the sun's top edge is
    /// above the horizon by this criterion (SPA eq. 42 note).
    double atmos_refract_deg = 0.5667;
};

/// Intermediate and final values of the SPA (degrees unless stated), named as in the paper.
struct SpaResult {
    double jd = 0, jde = 0, jc = 0, jce = 0, jme = 0;
    double l_deg = 0, b_deg = 0, r_au = 0;  ///< heliocentric longitude, latitude, radius (eq. 9-11)
    double delta_psi_deg = 0, delta_epsilon_deg = 0;  ///< nutation (eq. 20-21)
    double epsilon_deg = 0;                           ///< true obliquity (eq. 25)
    double lambda_deg = 0;                            ///< apparent sun longitude (eq. 27)
    double nu_deg = 0;                    ///< apparent sidereal time at Greenwich (eq. 29)
    double alpha_deg = 0, delta_deg = 0;  ///< geocentric right ascension, declination
    double h_deg = 0;                     ///< local hour angle (eq. 32)
    double alpha_prime_deg = 0, delta_prime_deg = 0, h_prime_deg = 0;  ///< topocentric (eq. 36-38)
    double e0_deg = 0;          ///< topocentric elevation without refraction (eq. 41)
    double refraction_deg = 0;  ///< atmospheric refraction correction (eq. 42)
    double elevation_deg = 0;   ///< e = e0 + Δe (eq. 43)
    double zenith_deg = 0;      ///< θ = 90 - e (eq. 44)
    double azimuth_deg = 0;     ///< from north, clockwise (eastward), [0, 360) (eq. 46)
};

/// Runs the SPA. InvalidArgument names the bad field and its valid range (year -2000..6000,
/// latitude, longitude, month/day/time, pressure 0..5000 hPa, temperature -273..6000 °C, |ΔT| <=
/// 8000 s).
StatusOr<SpaResult> ComputeSolarPosition(const SpaInput& in);

}  // namespace nave
