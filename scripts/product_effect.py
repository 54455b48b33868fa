#!/usr/bin/env python3
"""How much of the Cornell box's remaining difference from Mitsuba 3 comes from multiplying
spectra: rust-v's full-spectrum path carries 36 bins and the colour integral interpolates the
*product* of the reflectances along a path between bins, while Mitsuba (and rust-v's
`--wavelengths continuous`) multiplies the *interpolated* reflectances at each wavelength.

Why: with Mitsuba's CMF table and constant (scripts/mitsuba_weights.py) every region of
scenes/cornell-lambert.ron agrees with Mitsuba within noise except the green wall's red channel.
Light that reached the green wall from the red wall carries rho_green * rho_red, whose two
interpolations differ most in red (rho_red rises steeply where rho_green falls). This script

1. integrates, at 0.01 nm against the 1 nm CIE table, each product of two or three of the
   scene's reflectances (../shared/peers/mitsuba/spectra.csv) both ways and prints the relative
   difference per linear sRGB channel (an independent calculation, no renderer involved);
2. given two renders, one of the scene and one with the red wall black
   (`Lambertian(reflectance: Constant(0))`), takes the share of each region's light that went
   via the red wall, and predicts the green wall's difference as share * (green*red effect).

Usage: scripts/product_effect.py [FULL.exr NO_RED_WALL.exr]   (numpy; OpenEXR for renders)
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "../../shared")
XYZ_TO_SRGB = np.array([[3.240479, -1.537150, -0.498535],
                        [-0.969256, 1.875991, 0.041556],
                        [0.055648, -0.204043, 1.057311]])


def effects():
    d = np.loadtxt(os.path.join(SHARED, "peers/mitsuba/spectra.csv"), delimiter=",", skiprows=5)
    wl, rho = d[:, 0], {"red": d[:, 1], "green": d[:, 2], "white": d[:, 3], "blue": d[:, 4]}
    cmf_rows = np.loadtxt(os.path.join(SHARED, "data/cmf_1931_2deg_360_830_1nm.csv"), delimiter=",", skiprows=1)
    lam = np.linspace(360, 830, 47001)
    cmf = np.stack([np.interp(lam, cmf_rows[:, 0], cmf_rows[:, k]) for k in (1, 2, 3)], 1)

    def rgb(f):
        return XYZ_TO_SRGB @ np.trapezoid(cmf * f[:, None], lam, axis=0)

    out = {}
    for combo in [("green", "red"), ("green", "white"), ("green", "green", "white"), ("red", "white"),
                  ("red", "green", "white")]:
        # np.interp is flat beyond the ends, as the scene spec extends the 380-730 nm data.
        bins = rgb(np.interp(lam, wl, np.prod([rho[c] for c in combo], axis=0)))
        per_lambda = rgb(np.prod([np.interp(lam, wl, rho[c]) for c in combo], axis=0))
        out[combo] = bins / per_lambda - 1
        print(f"{'*'.join(combo):18} interpolated product / product of interpolations - 1: "
              + " ".join(f"{ch} {100 * v:+.3f}%" for ch, v in zip("RGB", out[combo])))
    return out


def main():
    eff = effects()
    if len(sys.argv) < 3:
        return
    sys.path.insert(0, HERE)
    from cornell_regions import masks, read_rgb

    full, nored = read_rgb(sys.argv[1]), read_rgb(sys.argv[2])
    m = masks()
    for name in ("right (green)", "back", "floor"):
        share = 1 - nored[m[name]].mean(0) / full[m[name]].mean(0)
        print(f"{name}: share of light via the red wall (R, G, B) {np.round(share, 3)}")
    share = 1 - nored[m["right (green)"]].mean(0) / full[m["right (green)"]].mean(0)
    pred = 100 * share * eff[("green", "red")]
    print("predicted difference on the green wall (bins vs Mitsuba's per-wavelength products): "
          + " ".join(f"{ch} {v:+.3f}%" for ch, v in zip("RGB", pred)))


if __name__ == "__main__":
    main()
