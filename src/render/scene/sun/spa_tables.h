#pragma once
// Periodic terms of the NREL Solar Position Algorithm: Reda & Andreas, "Solar position algorithm
// for solar radiation applications", NREL/TP-560-34302 (2003, rev. 2008), Solar Energy 76(5)
// 577-589 (2004), Table A4.2 (Earth periodic terms, from VSOP87 via Meeus) and Table A4.3 (nutation
// in longitude and obliquity, from Meeus, Astronomical Algorithms, Table 22.A).

namespace nave::spa {

/// One periodic term A cos(B + C x) of the Earth heliocentric series.
struct PeriodicTerm {
    double a, b, c;
};

/// L0..L5, B0..B1, R0..R4: each a span of terms.
struct TermSeries {
    const PeriodicTerm* terms;
    int count;
};

extern const TermSeries kL[6];
extern const TermSeries kB[2];
extern const TermSeries kR[5];

/// One of the 63 nutation terms: multipliers Y0..Y4 of the arguments X0..X4 and coefficients a, b
/// (longitude, 0.0001 arcsec) and c, d (obliquity).
struct NutationTerm {
    int y[5];
    double a, b, c, d;
};
inline constexpr int kNumNutationTerms = 63;
extern const NutationTerm kNutation[kNumNutationTerms];

}  // namespace nave::spa
