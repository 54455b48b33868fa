#!/usr/bin/env python3
"""Error slopes and time to equal error of the samplers, from scripts/sampler_study.sh.

    scripts/sampler_study.py OUT [--metric mse_lin] [--from-spp 4]

Reads OUT/<sampler>-<round>/<scene>-converge.csv for the samplers `sobol` and
`independent`, takes per scene, method, sampler and spp the median over seeds and
rounds of the metric and of the render seconds, and prints a Markdown table:
- slope: least-squares fit of log(metric) against log(spp) over spp >= --from-spp
  (independent sampling of an unbiased method: about -1);
- metric at the largest spp for both samplers, and their ratio (equal spp);
- seconds at the largest spp for both samplers (the cost per sample);
- time to equal error: the seconds `sobol` needs to reach the error `independent`
  reaches at the largest spp (log-log interpolation between checkpoints), divided by
  the seconds `independent` took (below 1: sobol is faster to that error).
"""
import collections, csv, glob, math, os, statistics, sys

def main():
    args = sys.argv[1:]
    out, metric, from_spp = args[0], "mse_lin", 4
    if "--metric" in args:
        metric = args[args.index("--metric") + 1]
    if "--from-spp" in args:
        from_spp = int(args[args.index("--from-spp") + 1])
    data = collections.defaultdict(lambda: collections.defaultdict(list))
    for path in glob.glob(os.path.join(out, "*-*", "*-converge.csv")):
        sampler = os.path.basename(os.path.dirname(path)).rsplit("-", 1)[0]
        with open(path) as f:
            for r in csv.DictReader(f):
                key = (r["scene"], r["method"], sampler)
                data[key][int(r["spp"])].append((float(r["seconds"]), float(r[metric])))
    curves = {}
    for key, by_spp in data.items():
        curves[key] = [(spp, statistics.median(t for t, _ in v), statistics.median(m for _, m in v))
                       for spp, v in sorted(by_spp.items())]
    print(f"| scene | method | slope sobol | slope independent | {metric} at the largest spp: sobol / independent | seconds there: sobol / independent | time to independent's final error: sobol / independent |")
    print("|---|---|---|---|---|---|---|")
    for scene, method in sorted({(k[0], k[1]) for k in curves}):
        s, i = curves.get((scene, method, "sobol")), curves.get((scene, method, "independent"))
        if not s or not i:
            continue
        def slope(c):
            pts = [(math.log(spp), math.log(m)) for spp, _, m in c if spp >= from_spp and m > 0]
            mx = sum(x for x, _ in pts) / len(pts)
            my = sum(y for _, y in pts) / len(pts)
            return sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
        target, t_ind, spp_max = i[-1][2], i[-1][1], i[-1][0]
        t_sobol = None
        for (s0, t0, m0), (s1, t1, m1) in zip(s, s[1:]):
            if m0 >= target >= m1 and m0 > m1:
                f = (math.log(m0) - math.log(target)) / (math.log(m0) - math.log(m1))
                t_sobol = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
                break
        if t_sobol is None and s[0][2] <= target:
            t_sobol = s[0][1]
        ratio = f"{t_sobol / t_ind:.2f} ({t_sobol:.2f} s / {t_ind:.2f} s)" if t_sobol else "not reached"
        print(f"| {scene} | {method} | {slope(s):.2f} | {slope(i):.2f} | {s[-1][2]:.3e} / {i[-1][2]:.3e} = {s[-1][2] / i[-1][2]:.2f} at {spp_max} | {s[-1][1]:.2f} / {i[-1][1]:.2f} | {ratio} |")

if __name__ == "__main__":
    main()
