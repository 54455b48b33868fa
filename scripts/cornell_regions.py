#!/usr/bin/env python3
"""Region-by-region comparison of a render of scenes/cornell-lambert.ron with the Mitsuba 3
reference (../shared/peers/mitsuba/refs/cornell.exr), both linear sRGB EXR at 256x256.

Why: image means hide colour errors on saturated surfaces; this script reports the mean of
every region (each wall, the floor, the ceiling, the light, the blue sphere) per channel and the
relative difference, with the standard error of the difference from the spread of the per-pixel differences.

Regions come from the scene geometry of SCENE-SPEC.md, not from the images: a pixel belongs to
a surface when the rays through its four corners and its centre all hit that surface first.

Usage: scripts/cornell_regions.py OURS.exr [REF.exr]   (needs numpy and OpenEXR from PyPI)
"""
import sys

import numpy as np
import OpenEXR

N = 256
T = np.tan(np.radians(22.5))
EYE = np.array([0.0, 1.0, 3.5])


def read_rgb(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def first_hit(px, py):
    """Name of the first surface hit by the ray through film position (px, py)."""
    d = np.array([(2 * px / N - 1) * T, (1 - 2 * py / N) * T, -1.0])
    d /= np.linalg.norm(d)
    best, name = np.inf, None
    for c, r, nm in (((-0.6, 1.7, -0.4), 0.2, "light"), ((0.3, 0.35, -0.2), 0.35, "sphere")):
        oc = EYE - np.array(c)
        b = oc @ d
        disc = b * b - (oc @ oc - r * r)
        if disc > 0:
            t = -b - np.sqrt(disc)
            if 1e-6 < t < best:
                best, name = t, nm
    planes = ((1, 0.0, "floor"), (1, 2.0, "ceiling"), (2, -1.0, "back"), (0, -1.0, "left (red)"), (0, 1.0, "right (green)"))
    for axis, val, nm in planes:
        if abs(d[axis]) < 1e-12:
            continue
        t = (val - EYE[axis]) / d[axis]
        if not (1e-6 < t < best):
            continue
        p = EYE + t * d
        ok = all(-1 - 1e-9 <= p[a] - (1 if a == 1 else 0) <= 1 + 1e-9 for a in range(3) if a != axis)
        if ok and p[2] <= 1.0:
            best, name = t, nm
    return name


def masks():
    out = {}
    for j in range(N):
        for i in range(N):
            hits = {first_hit(i + dx, j + dy) for dx, dy in ((0.01, 0.01), (0.99, 0.01), (0.01, 0.99), (0.99, 0.99), (0.5, 0.5))}
            if len(hits) == 1 and None not in hits:
                out.setdefault(hits.pop(), []).append((j, i))
    return {k: tuple(np.array(v).T) for k, v in out.items()}


def main():
    ours = read_rgb(sys.argv[1])
    ref = read_rgb(sys.argv[2] if len(sys.argv) > 2 else "../shared/peers/mitsuba/refs/cornell.exr")
    print(f"{'region':15} {'pixels':>6}  {'R':>18} {'G':>18} {'B':>18}   (ours/ref - 1, ± 1 s.e.)")
    worst = 0.0
    for name, idx in sorted(masks().items()):
        a, b = ours[idx], ref[idx]
        cells = []
        for c in range(3):
            ma, mb = a[:, c].mean(), b[:, c].mean()
            rel = ma / mb - 1
            # Pixel noise is independent: the spread of the per-pixel differences gives the
            # standard error of the difference of the means (shading gradients cancel).
            se = np.sqrt((a[:, c] - b[:, c]).var() / len(a)) / mb
            worst = max(worst, abs(rel))
            cells.append(f"{100 * rel:+7.3f}% ±{100 * se:5.3f}%")
        print(f"{name:15} {len(a):6}  " + " ".join(f"{c:>18}" for c in cells))
    print(f"worst |difference|: {100 * worst:.3f}%")


if __name__ == "__main__":
    main()
