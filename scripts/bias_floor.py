#!/usr/bin/env python3
"""Bias floors and crossover times, from `rust-v converge` summaries.

    scripts/bias_floor.py study/*-summary.csv [--metric mse_lin] [--min-spp 16] [--against path]

An unbiased method's error against a reference falls as MSE(n) = a / n + c,
where `c` is the reference's own noise, the same for every method; a biased
method's levels off at c + B, B being its squared bias. The script fits
each method alone, MSE = a / spp + floor (least squares, weights 1 / MSE²,
medians over seeds, checkpoints from --min-spp on), and prints `a`, the
floor and the seconds per spp; the squared bias of the --against method
(default `path`) is B = floor(against) - floor(auto). B is the difference of
two fitted floors, each a small part of the error at the last checkpoint:
treat it as an estimate to within a factor of about two, and measure it with
a high-spp study where it matters (identical methods give B = 0 exactly).

Error against time: a method reaching the reference's floor plus `e` takes
t(e) = (a / e) * (seconds per spp). For `auto` against the biased method,
whose error never drops below B, `auto` is faster for every target below
e* where a_auto * s_auto / e* = a_path * s_path / (e* - B), that is
e* = B * A / (A - P) with A = a_auto * s_auto and P = a_path * s_path. The
script prints e* and the time and spp `auto` needs to reach it. The linear
MSE (`mse_lin`) is the default metric: the thesis's 16-bit sRGB MSE clamps
fireflies at low spp and so does not follow the 1/n law.
"""
import collections
import csv
import sys


def solve(m, v):
    """Solves the small dense system m x = v (Gaussian elimination, partial pivoting)."""
    n = len(v)
    m = [row[:] + [v[i]] for i, row in enumerate(m)]
    for i in range(n):
        p = max(range(i, n), key=lambda r: abs(m[r][i]))
        m[i], m[p] = m[p], m[i]
        for r in range(i + 1, n):
            f = m[r][i] / m[i][i]
            for k in range(i, n + 1):
                m[r][k] -= f * m[i][k]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (m[i][n] - sum(m[i][k] * x[k] for k in range(i + 1, n))) / m[i][i]
    return x


def fit(series):
    """Weighted least squares of m = a_j / n + c over series j of (n, m) points,
    one a_j per series and one shared c: returns ([a_j], c). (Called with one
    series per method.)"""
    k = len(series)
    ata = [[0.0] * (k + 1) for _ in range(k + 1)]
    atb = [0.0] * (k + 1)
    for j, pts in enumerate(series):
        for n, m in pts:
            w = 1.0 / (m * m)
            row = [0.0] * (k + 1)
            row[j] = 1.0 / n
            row[k] = 1.0
            for p in range(k + 1):
                atb[p] += w * row[p] * m
                for q in range(k + 1):
                    ata[p][q] += w * row[p] * row[q]
    x = solve(ata, atb)
    return x[:k], x[k]


def main():
    args = sys.argv[1:]
    metric, min_spp, against, files = "mse_lin", 16.0, "path", []
    i = 0
    while i < len(args):
        if args[i] == "--metric":
            metric = args[i + 1]; i += 2
        elif args[i] == "--min-spp":
            min_spp = float(args[i + 1]); i += 2
        elif args[i] == "--against":
            against = args[i + 1]; i += 2
        else:
            files.append(args[i]); i += 1
    for path in files:
        rows = collections.defaultdict(list)
        with open(path) as f:
            for r in csv.DictReader(f):
                rows[r["method"]].append(r)
        scene = next(iter(rows.values()))[0]["scene"]
        print(f"## {scene} ({metric}, fit MSE = a/spp + c from {min_spp:.0f} spp)")
        print("| method | a | floor | s per spp | a x s per spp |")
        print("|---|---|---|---|---|")
        pts, sps = {}, {}
        for m, rs in rows.items():
            pts[m] = [(float(r["spp"]), float(r[metric + "_median"])) for r in rs if float(r["spp"]) >= min_spp]
            last = max(rs, key=lambda r: float(r["spp"]))
            sps[m] = float(last["seconds_median"]) / float(last["spp"])
        res = {}
        for m in rows:
            if len(pts[m]) >= 3:
                (a,), floor = fit([pts[m]])
                res[m] = (max(a, 0.0), floor)
        for m, (a, floor) in res.items():
            print(f"| {m} | {a:.4g} | {floor:.4g} | {sps[m]:.4g} | {a * sps[m]:.4g} |")
        if "auto" in res and against in res:
            (aa, ca), (ap, cp) = res["auto"], res[against]
            sa, sp = sps["auto"], sps[against]
            bias = cp - ca
            big_a, big_p = aa * sa, ap * sp
            print(f"\n{against}: squared bias B = {bias:.4g}")
            if big_p == 0:
                print(f"{against} does not converge (a = 0): auto is faster below {bias:.4g}")
            elif bias <= 0:
                print(f"no measurable bias: `auto` is never faster than {against} by this fit")
            elif big_a <= big_p:
                print(f"auto is faster than {against} at every target")
            else:
                e = bias * big_a / (big_a - big_p)
                print(
                    f"auto is faster than {against} below an error of {e:.4g} above the reference floor: "
                    f"from {big_a / e:.1f} s and {aa / e:.0f} spp of auto on"
                )
        print()


main()
