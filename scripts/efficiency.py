#!/usr/bin/env python3
"""Relative efficiency of methods from a `rust-v converge` CSV (every record).

    scripts/efficiency.py study/cornell-converge.csv [--base path]

For each sample count and method: the mean linear MSE over the seeds (with
its standard error), the median seconds, and the time to equal error
relative to the base method, (t · MSE) / (t_base · MSE_base). Since MSE
falls as 1/spp for an unbiased method, t · MSE is a method's time to any
fixed error (up to a constant), so the ratio is how much longer (> 1) or
shorter (< 1) the method takes than the base to reach the same error.
Needs a reference much better than the renders (its own noise adds the same
constant to every MSE; keep it below ~5% of the smallest MSE compared).
"""
import csv, statistics as st, sys

def main():
    args = sys.argv[1:]
    base = "path"
    if "--base" in args:
        i = args.index("--base")
        base = args[i + 1]
        del args[i:i + 2]
    rows = list(csv.DictReader(open(args[0])))
    by = {}
    for r in rows:
        by.setdefault((int(r["spp"]), r["method"]), []).append((float(r["mse_lin"]), float(r["seconds"])))
    print("| spp | method | seeds | linear MSE | s.e. | seconds (median) | time to equal error / " + base + " |")
    print("|---|---|---|---|---|---|---|")
    for spp in sorted({k[0] for k in by}):
        ref = by.get((spp, base))
        for (s, m), v in sorted(by.items()):
            if s != spp:
                continue
            mse = st.mean(x for x, _ in v)
            se = st.stdev(x for x, _ in v) / len(v) ** 0.5 if len(v) > 1 else float("nan")
            t = st.median(y for _, y in v)
            ratio = "-"
            if ref:
                ratio = f"{t * mse / (st.median(y for _, y in ref) * st.mean(x for x, _ in ref)):.2f}"
            print(f"| {spp} | {m} | {len(v)} | {mse:.4e} | {se:.1e} | {t:.3f} | {ratio} |")

if __name__ == "__main__":
    main()
