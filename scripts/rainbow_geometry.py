#!/usr/bin/env python3
"""Geometry of scenes/prism-rainbow.ron and an independent prediction of its rainbow.

A white collimated beam travels along -z through the N-SF11 prism of
scenes/prism.ron (meshes/prism.obj, made by scripts/prism_geometry.py), which
it meets at minimum deviation for 589.3 nm, and fans out onto a white screen
perpendicular to the 589.3 nm exit ray. This script traces the beam's axis in
2-D (the xz plane) in f64 with Snell's law and the Sellmeier equation,
separately from the renderer, and prints:
- the screen's placement (centre, normal, horizontal axis) for the scene file;
- for each bin wavelength (380..730 nm), the signed distance along the
  screen's horizontal axis at which that wavelength's beam centre lands.
tests/bdpt.rs checks the renderer's spectral channels against these numbers.
Run from the repository root; prints only.
"""
import math

B = [1.73759695, 0.313747346, 1.89878101]
C = [0.013188707, 0.0623068142, 155.23629]


def n(lam):
    l2 = (lam / 1000) ** 2
    return math.sqrt(1 + sum(b * l2 / (l2 - c) for b, c in zip(B, C)))


# The prism's cross-section (x, z) from meshes/prism.obj.
P = [(0.541902799, -3.757805592), (-1.854460587, -3.625735454), (-0.541902799, -1.616458954)]
CX = sum(p[0] for p in P) / 3
CZ = sum(p[1] for p in P) / 3
EDGES = [(P[0], P[1]), (P[1], P[2]), (P[2], P[0])]


def outward(p, q):
    ex, ez = q[0] - p[0], q[1] - p[1]
    nn = (ez, -ex)
    L = math.hypot(*nn)
    nn = (nn[0] / L, nn[1] / L)
    mx, mz = (p[0] + q[0]) / 2 - CX, (p[1] + q[1]) / 2 - CZ
    return nn if nn[0] * mx + nn[1] * mz > 0 else (-nn[0], -nn[1])


def refract(d, nrm, eta):
    c = -(d[0] * nrm[0] + d[1] * nrm[1])
    if c < 0:
        nrm = (-nrm[0], -nrm[1])
        c = -c
        eta = 1 / eta
    k = 1 - (1 - c * c) / (eta * eta)
    if k < 0:
        return None
    ct = math.sqrt(k)
    return (d[0] / eta + (c / eta - ct) * nrm[0], d[1] / eta + (c / eta - ct) * nrm[1])


def seg_hit(o, d, p, q):
    ex, ez = q[0] - p[0], q[1] - p[1]
    den = d[0] * (-ez) - d[1] * (-ex)
    if abs(den) < 1e-12:
        return None
    rx, rz = p[0] - o[0], p[1] - o[1]
    t = (rx * (-ez) - rz * (-ex)) / den
    u = (d[0] * rz - d[1] * rx) / den
    return t if t > 1e-9 and 0 <= u <= 1 else None


def trace(o, d, lam):
    """The ray after its two refractions (entry and exit)."""
    eta = n(lam)
    for _ in range(2):
        best = None
        for p, q in EDGES:
            t = seg_hit(o, d, p, q)
            if t and (best is None or t < best[0]):
                best = (t, p, q)
        t, p, q = best
        o = (o[0] + d[0] * t, o[1] + d[1] * t)
        nd = refract(d, outward(p, q), eta)
        L = math.hypot(*nd)
        d = (nd[0] / L, nd[1] / L)
        o = (o[0] + d[0] * 1e-9, o[1] + d[1] * 1e-9)
    return o, d


o0, d0 = trace((0.0, 2.0), (0.0, -1.0), 589.3)
DIST = 5.0
centre = (o0[0] + d0[0] * DIST, o0[1] + d0[1] * DIST)
normal = (-d0[0], -d0[1])
axis = (-normal[1], normal[0])  # horizontal, in the screen plane
print("exit point (%.6f, 0, %.6f), direction (%.6f, 0, %.6f)" % (o0[0], o0[1], d0[0], d0[1]))
print("screen centre (%.6f, 0, %.6f), normal (%.6f, 0, %.6f), axis (%.6f, 0, %.6f)" % (centre + normal + axis))
print("band centre along the screen axis per wavelength (nm: offset):")
for lam in range(380, 740, 10):
    o, d = trace((0.0, 2.0), (0.0, -1.0), lam)
    # Intersect with the screen plane (point centre, normal).
    t = ((centre[0] - o[0]) * normal[0] + (centre[1] - o[1]) * normal[1]) / (d[0] * normal[0] + d[1] * normal[1])
    hit = (o[0] + d[0] * t, o[1] + d[1] * t)
    off = (hit[0] - centre[0]) * axis[0] + (hit[1] - centre[1]) * axis[1]
    print("  %d: %.6f" % (lam, off))
