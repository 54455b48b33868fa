#!/usr/bin/env python3
"""Time (and spp) each method needs to reach a fixed error, from `rust-v converge` summaries.

    scripts/time_to_mse.py study/*-summary.csv [--metric mse] [--targets 1e8,3e7]

For each scene and method, reads the median seconds and median metric at every
checkpoint and interpolates log(seconds) against log(metric) between the two
checkpoints that bracket the target (a method that never reaches it prints "-").
Default targets: per scene, the median metric `path` reaches at 64 spp and at
the last checkpoint. Also prints the hero/random ratios at equal spp (the
thesis's) and at equal time (MSE at the time hero took).
"""
import csv, math, sys, collections

def load(path):
    rows = collections.defaultdict(list)
    with open(path) as f:
        for r in csv.DictReader(f):
            rows[r["method"]].append(r)
    scene = next(iter(rows.values()))[0]["scene"]
    return scene, rows

def at(rows, metric, target, key):
    pts = [(float(r["seconds_median"]), float(r["spp"]), float(r[metric + "_median"])) for r in rows]
    for (t0, s0, m0), (t1, s1, m1) in zip(pts, pts[1:]):
        if m0 >= target >= m1 and m0 > m1:
            f = (math.log(m0) - math.log(target)) / (math.log(m0) - math.log(m1))
            a, b = (t0, t1) if key == "s" else (s0, s1)
            return math.exp(math.log(a) + f * (math.log(b) - math.log(a)))
    if pts and pts[0][2] <= target:
        return pts[0][0] if key == "s" else pts[0][1]
    return None

def main():
    args = sys.argv[1:]
    metric = "mse"
    targets = None
    files = []
    i = 0
    while i < len(args):
        if args[i] == "--metric":
            metric = args[i + 1]; i += 2
        elif args[i] == "--targets":
            targets = [float(x) for x in args[i + 1].split(",")]; i += 2
        else:
            files.append(args[i]); i += 1
    for path in files:
        scene, rows = load(path)
        ts = targets
        if ts is None and "path" in rows:
            p = rows["path"]
            m64 = [float(r[metric + "_median"]) for r in p if r["spp"] == "64"]
            ts = m64 + [float(p[-1][metric + "_median"])]
        print(f"## {scene} ({metric})")
        print("| method | " + " | ".join(f"s to {t:.3g} | spp" for t in ts) + " |")
        for m, r in rows.items():
            cells = []
            for t in ts:
                s = at(r, metric, t, "s"); n = at(r, metric, t, "n")
                cells.append(f"{s:.2f} | {n:.0f}" if s else "- | -")
            print(f"| {m} | " + " | ".join(cells) + " |")
        if "hero" in rows and "random" in rows:
            h, rr = rows["hero"], rows["random"]
            ratio_spp = float(h[-1][metric + "_median"]) / float(rr[-1][metric + "_median"])
            # Equal time: both curves interpolated (log-log) at the shorter of the two total times.
            def metric_at(rows_, t):
                pts = [(float(r["seconds_median"]), float(r[metric + "_median"])) for r in rows_]
                for (t0, m0), (t1, m1) in zip(pts, pts[1:]):
                    if t0 <= t <= t1 and t0 > 0:
                        f = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
                        return math.exp(math.log(m0) + f * (math.log(m1) - math.log(m0)))
                return None
            t = min(float(h[-1]["seconds_median"]), float(rr[-1]["seconds_median"]))
            mh, mr = metric_at(h, t), metric_at(rr, t)
            eq_time = f"{mh / mr:.3f}" if mh and mr else "-"
            print(f"hero/random {metric} at {h[-1]['spp']} spp: {ratio_spp:.3f}; at equal time ({t:.1f} s): {eq_time}")
        print()

main()
