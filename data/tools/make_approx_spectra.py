#!/usr/bin/env python3
"""Builds data/stained_glass_approx.csv and data/stone_approx.csv: APPROXIMATE spectra (no public measured
data of these materials was available to nave). Run from data/: python3 tools/make_approx_spectra.py.
Band positions (see data/SOURCES.md):
  Fe3+ UV charge-transfer edge (< 400 nm) and Fe2+ band at ~1050 nm in forest/clear glass (Bamford,
  Colour Generation and Control in Glass, 1977, ch. 4); Co2+ tetrahedral triplet at ~535, 595, 645 nm
  (Bamford ch. 4; Weyl, Coloured Glasses, 1951); Cu2+ broad band at ~800 nm (Weyl 1951); copper-ruby red:
  colloidal Cu absorption edge near 580-600 nm (Weyl 1951); yellow: silver-stain / amber edge near 500 nm.
"""
import math


def band(l, c, w_um, a):  # Gaussian absorption band in wavenumber (1/um), absorbance a at its centre
    x = (1000 / l - 1000 / c) / w_um
    return a * math.exp(-x * x)


def edge(l, c, s, a):  # absorbance a below wavelength c (nm), logistic width s (nm)
    return a / (1 + math.exp((l - c) / s))


def clear(l):  # pale greenish "white" glass, ~3 mm
    return 0.02 + edge(l, 372, 10, 1.2) + band(l, 1050, 0.35, 0.35)


GLASS = {
    "glass_clear": clear,
    "glass_blue": lambda l: clear(l) + band(l, 535, 0.09, 0.9) + band(l, 595, 0.07, 1.6)
    + band(l, 645, 0.08, 1.5) + edge(l, 420, 10, 0.3),
    "glass_red": lambda l: clear(l) + edge(l, 592, 11, 5.0),
    "glass_yellow": lambda l: clear(l) + edge(l, 505, 16, 3.0),
    "glass_green": lambda l: clear(l) + band(l, 800, 0.28, 1.6) + edge(l, 478, 14, 2.2),
}


def limestone(l):  # light buff limestone: Fe3+ edge in the blue, gently rising to the red
    return 0.58 + 0.06 * (l - 600) / 230 - 0.22 / (1 + math.exp((l - 455) / 28))


STONE = {
    "limestone": limestone,
    "limestone_dark": lambda l: 0.62 * limestone(l) - 0.02,
    "roof_slate": lambda l: 0.085 + 0.008 * (l - 550) / 280,
    # Pale polished limestone/marble tile and red terracotta tile (Fe2O3 edge near 560 nm).
    "floor_tile_light": lambda l: 0.95 * limestone(l) + 0.08,
    "floor_tile_dark": lambda l: 0.07 + 0.30 / (1 + math.exp(-(l - 575) / 22)),
    # Aged oak: low in the blue, rising through the red (shape of published wood spectra).
    "wood": lambda l: 0.06 + 0.36 / (1 + math.exp(-(l - 610) / 45)),
}

R = 0.04  # Fresnel reflectance of one face at normal incidence, n = 1.5
with open("stained_glass_approx.csv", "w") as f:
    f.write("# APPROXIMATIONS, not measurements: total normal-incidence transmittance of ~3 mm panes of medieval-\n")
    f.write("# style coloured glass, built by tools/make_approx_spectra.py from published absorption-band positions\n")
    f.write("# (see SOURCES.md): absorbance A = Gaussian bands in wavenumber + logistic edges, tau = 10^-A,\n")
    f.write("# T = (1-R)^2 tau / (1 - R^2 tau^2), R = 0.04 (two faces, n = 1.5).\n")
    f.write("wavelength_nm," + ",".join(GLASS) + "\n")
    for l in range(360, 831, 5):
        vals = []
        for m in GLASS.values():
            tau = 10 ** (-m(l))
            vals.append((1 - R) ** 2 * tau / (1 - R * R * tau * tau))
        f.write(f"{l}," + ",".join(f"{v:.4f}" for v in vals) + "\n")
with open("stone_approx.csv", "w") as f:
    f.write("# APPROXIMATIONS, not measurements: diffuse spectral reflectance of building materials, built by\n")
    f.write("# tools/make_approx_spectra.py after the shape of published stone, terracotta and wood spectra (ECOSTRESS/ASTER library,\n")
    f.write("# Baldridge et al. 2009; USGS splib07, Kokaly et al. 2017). See SOURCES.md.\n")
    f.write("wavelength_nm," + ",".join(STONE) + "\n")
    for l in range(360, 831, 10):
        f.write(f"{l}," + ",".join(f"{m(l):.4f}" for m in STONE.values()) + "\n")
