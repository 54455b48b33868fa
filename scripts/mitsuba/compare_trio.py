#!/usr/bin/env python3
"""Region-by-region comparison of scenes/materials-trio.ron (rust-v) with
scripts/mitsuba/materials-trio.xml (Mitsuba 3): each sphere's centre and the
floor in front of it, as mean linear sRGB and luminance Y, with the standard
error of the region mean from the pixel spread.

Run with the Mitsuba harness's venv python (it has numpy and mitsuba, used
only to read EXR):
    ~/.cache/peers/mitsuba-venv/bin/python scripts/mitsuba/compare_trio.py RUSTV.exr MITSUBA.exr
"""
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

RES = 256
T = np.tan(np.radians(22.5))
EYE = np.array([0.0, 1.0, 3.5])


def project(p):
    d = np.asarray(p, float) - EYE
    return RES / 2 * (1 + d[0] / -d[2] / T), RES / 2 * (1 - d[1] / -d[2] / T)


REGIONS = []
for name, x in [("gold", -0.6), ("rough copper", 0.0), ("rough glass", 0.6)]:
    REGIONS.append((f"{name} sphere, centre", project([x, 0.25, 0.0]), 8))
    # Where the normal is (0, 0.8, 0.6): the sphere mirrors the ceiling and the light's surroundings.
    REGIONS.append((f"{name} sphere, top", project([x, 0.45, 0.15]), 4))
    REGIONS.append((f"floor before {name}", project([x, 0.0, 0.35]), 4))


def load(path):
    a = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False))
    return a[:, :, :3].astype(np.float64)


def main():
    a, b = load(sys.argv[1]), load(sys.argv[2])
    y = np.array([0.2126, 0.7152, 0.0722])
    print("| region | pixels | rust-v RGB | Mitsuba RGB | Y rust-v | Y Mitsuba | ratio | z |")
    print("|---|---|---|---|---|---|---|---|")
    for name, (cx, cy), h in REGIONS:
        x0, x1, y0, y1 = int(cx) - h, int(cx) + h, int(cy) - h, int(cy) + h
        ra, rb = a[y0:y1, x0:x1].reshape(-1, 3), b[y0:y1, x0:x1].reshape(-1, 3)
        ya, yb = ra @ y, rb @ y
        se = np.sqrt(ya.var(ddof=1) / len(ya) + yb.var(ddof=1) / len(yb))
        fmt = lambda v: "(" + ", ".join(f"{c:.4f}" for c in v) + ")"
        print(f"| {name} | x {x0}-{x1}, y {y0}-{y1} | {fmt(ra.mean(0))} | {fmt(rb.mean(0))} | {ya.mean():.4f} | "
              f"{yb.mean():.4f} | {ya.mean() / yb.mean():.3f} | {(ya.mean() - yb.mean()) / se:+.1f} |")
    print(f"| whole image | | {fmt(a.reshape(-1, 3).mean(0))} | {fmt(b.reshape(-1, 3).mean(0))} | "
          f"{(a.reshape(-1, 3) @ y).mean():.4f} | {(b.reshape(-1, 3) @ y).mean():.4f} | "
          f"{(a.reshape(-1, 3) @ y).mean() / (b.reshape(-1, 3) @ y).mean():.3f} | |")


if __name__ == "__main__":
    main()
