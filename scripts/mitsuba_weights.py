#!/usr/bin/env python3
"""Region-by-region comparison of a --spectral render of scenes/cornell-lambert.ron with the
Mitsuba 3 reference, once with rust-v's colour integral and once with Mitsuba's.

Why: rust-v's pixel colour is the exact integral of the interpolated spectrum against the 1 nm
CIE 1931 table, normalised so a flat spectrum has Y = 1 (src/color/cie.rs). Mitsuba 3
integrates against its own 95-sample 5 nm table, linearly interpolated, times the constant
1/106.7502593994 (flat Y = 1.001; ../shared/peers/mitsuba/SCENE-SPEC.md section 7). The 36
spectral channels of a --spectral EXR hold the per-bin radiance, so the same render can be
integrated Mitsuba's way: W_b = k * integral(cmf_5nm(l) * tent_b(l) dl) over 360-830 nm, each
5 nm piece a quadratic integrated exactly by Simpson's rule (bin centres are table rows), with
tent_b the interpolation tent of bin b (end bins flat to 360 and 830 nm), exactly as
src/color/cie.rs `tent_weights` does for the 1 nm table. Then XYZ -> linear sRGB with Mitsuba's
matrix (rust-v uses the same one).

Regions and standard errors as scripts/cornell_regions.py (imported from there).

With --continuous CONT.exr (the same scene rendered with `--integrator spectral --wavelengths
continuous`, which multiplies the interpolated spectra at each wavelength as Mitsuba does, instead
of interpolating the per-bin products), a last column adds to CONT's region means the difference
Mitsuba's weights make on OURS: Mitsuba's whole colour integral, up to third-order cross terms.

Usage: scripts/mitsuba_weights.py OURS.exr [--continuous CONT.exr] [--ref REF.exr] [--cmf CMF.csv]
(numpy and OpenEXR from PyPI)
Prints a Markdown table: region, channel, rust-v and Mitsuba means (linear sRGB), their relative
difference, its standard error, the difference with Mitsuba's weights, and that in standard errors.
"""
import argparse
import os
import sys

import numpy as np
import OpenEXR

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cornell_regions import masks, read_rgb  # noqa: E402

K = 1.0 / 106.7502593994
XYZ_TO_SRGB = np.array([[3.240479, -1.537150, -0.498535],
                        [-0.969256, 1.875991, 0.041556],
                        [0.055648, -0.204043, 1.057311]])
BINS = [380 + 10 * b for b in range(36)]


def tent(b, lam):
    x = (lam - 380.0) / 10.0 - b
    if (b == 0 and x <= 0) or (b == 35 and x >= 0):
        return 1.0
    return max(1.0 - abs(x), 0.0)


def mitsuba_weights(path):
    rows = [list(map(float, line.split(","))) for line in open(path) if line[0].isdigit()]
    w = np.zeros((36, 3))
    for (l0, *c0), (l1, *c1) in zip(rows, rows[1:]):
        lm, h = 0.5 * (l0 + l1), l1 - l0
        for b in range(36):
            t0, tm, t1 = tent(b, l0), tent(b, lm), tent(b, l1)
            if t0 == tm == t1 == 0.0:
                continue
            for k in range(3):
                cm = 0.5 * (c0[k] + c1[k])
                w[b, k] += h / 6.0 * (c0[k] * t0 + 4.0 * cm * tm + c1[k] * t1)
    return w * K


def read_bins(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        names = [f"S0.{lam},000000nm" for lam in BINS]
        missing = [n for n in names if n not in ch]
        if missing:
            sys.exit(f"{path}: no spectral channel {missing[0]} (render with --spectral)")
        return np.stack([np.asarray(ch[n].pixels, dtype=np.float64) for n in names], axis=-1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("ours", help="a --spectral EXR render of scenes/cornell-lambert.ron (256x256)")
    ap.add_argument("--ref", default="../shared/peers/mitsuba/refs/cornell.exr")
    ap.add_argument("--cmf", default="../shared/peers/mitsuba/cmf_mitsuba.csv")
    ap.add_argument("--continuous", help="a render with --integrator spectral --wavelengths continuous: adds "
                    "a column with its region means plus the CMF correction measured on OURS")
    args = ap.parse_args()
    ours, ref, bins = read_rgb(args.ours), read_rgb(args.ref), read_bins(args.ours)
    cont = read_rgb(args.continuous) if args.continuous else None
    w = mitsuba_weights(args.cmf)
    print(f"Mitsuba weights: flat spectrum Y = {w[:, 1].sum():.6f}", file=sys.stderr)
    mits = (bins @ w) @ XYZ_TO_SRGB.T
    head = "| region | channel | rust-v | Mitsuba | difference | noise (1 s.e.) | with Mitsuba's weights | z |"
    rule = "|---|---|---|---|---|---|---|---|"
    if cont is not None:
        head += " continuous λ + Mitsuba's weights | noise | z |"
        rule += "---|---|---|"
    print(head)
    print(rule)
    for name, idx in sorted(masks().items()):
        a, b, m = ours[idx], ref[idx], mits[idx]
        for c, cname in enumerate("RGB"):
            mb = b[:, c].mean()
            rel, rel_m = a[:, c].mean() / mb - 1, m[:, c].mean() / mb - 1
            # Pixel noise is independent: the spread of the per-pixel differences gives the
            # standard error of the difference of the means (shading gradients cancel).
            se = np.sqrt((a[:, c] - b[:, c]).var() / len(a)) / mb
            row = (f"| {name} | {cname} | {a[:, c].mean():.4f} | {mb:.4f} | {100 * rel:+.2f}% | "
                   f"{100 * se:.2f}% | {100 * rel_m:+.2f}% | {rel_m / se:+.1f} |")
            if cont is not None:
                # The continuous render's products per wavelength, with the CMF table and constant
                # corrected by the difference Mitsuba's weights make on the binned render.
                k = cont[idx][:, c]
                rel_k = (k.mean() + m[:, c].mean() - a[:, c].mean()) / mb - 1
                se_k = np.sqrt((k - b[:, c]).var() / len(k)) / mb
                row += f" {100 * rel_k:+.2f}% | {100 * se_k:.2f}% | {rel_k / se_k:+.1f} |"
            print(row)

if __name__ == "__main__":
    main()
