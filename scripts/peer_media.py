#!/usr/bin/env python3
"""rust-v against Mitsuba 3 on a chromatic homogeneous medium in the Cornell box (issue 30).

scenes/cornell-medium.ron is the canonical Cornell box (SCENE-SPEC.md, = scenes/cornell-lambert.ron)
plus an index-matched sphere of a chromatic homogeneous medium. This script writes the same scene
for Mitsuba (the harness's scenes/cornell.xml with the `volpath` integrator and the sphere: a
`null` bsdf with an `interior` `homogeneous` medium), renders both scenes (with and without the
medium) with both renderers at several seeds, and compares them region by region.

The medium's spectra are converted exactly: Mitsuba takes σt and the albedo σs/σt. rust-v's
`Table` is linear between its nodes and flat beyond its ends; σt = σa + σs (σa constant) is
then linear between the same nodes, written at them; the albedo is not linear between nodes, so
it is written every 1 nm (Mitsuba interpolates linearly between the values given). Both are
written over 360-830 nm (Mitsuba's range; an irregular spectrum is zero outside its nodes).
Mitsuba's `hg` scatters forward for g > 0 like rust-v's (its sampled mean cosine with the
direction of travel is +g: checked with the harness's venv).

Noise: each renderer renders SEEDS independent images; a region's mean is the mean over the
seeds' images and its standard error comes from each pixel's spread across the seeds (pooled
over the region's pixels, whose samples are independent). z = (rust-v - Mitsuba) / sqrt(se_r² +
se_m²); agreement within noise means |z| below 3 in every region and channel, and the
blocks' z spread like a standard normal.

    ~/.cache/peers/mitsuba-venv/bin/python scripts/peer_media.py [--bin target/release/rust-v]
        [--seeds 4] [--mitsuba-spp 2048] [--rustv-spp 2048] [--scenes medium,plain]
        [--variant llvm_ad_spectral] [--integrator volpath] [--out DIR] [--compare-only] [--speed ROUNDS]

--speed ROUNDS then measures time to equal error on the medium scene (Mitsuba `volpath` and
`volpathmis` at 64 spp against the mean of Mitsuba's images, rust-v against the mean of its own;
see speed()). (scripts/peer_media.sh runs it with the venv's python.) Images go to DIR (default
/tmp/peer-media) and are reused when there (delete DIR to render afresh; a run with more
--seeds renders only the new ones); --compare-only renders nothing. Prints markdown tables.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _harness():
    """$HARNESS, else ../shared/peers/mitsuba beside this checkout or beside the main one (a worktree)."""
    if os.environ.get("HARNESS"):
        return os.path.realpath(os.environ["HARNESS"])
    roots = [HERE]
    try:
        common = subprocess.run(["git", "-C", HERE, "rev-parse", "--path-format=absolute", "--git-common-dir"],
                                capture_output=True, text=True, check=True).stdout.strip()
        roots.append(os.path.dirname(common))
    except (OSError, subprocess.CalledProcessError):
        pass
    for r in roots:
        h = os.path.join(r, "..", "shared", "peers", "mitsuba")
        if os.path.isdir(h):
            return os.path.realpath(h)
    sys.exit("no Mitsuba harness: set HARNESS (../shared/peers/mitsuba)")


HARNESS = _harness()
RES = 128

# The medium of scenes/cornell-medium.ron (checked against the file below).
SIGMA_A = 0.15
SIGMA_S = [(400, 4.0), (450, 3.0), (500, 2.0), (550, 1.4), (600, 1.0), (650, 0.7), (700, 0.5)]
G = 0.5
CENTER, RADIUS = (-0.4, 0.5, 0.3), 0.42


def sigma_s(lam):
    """rust-v's Table: linear between nodes, flat beyond the ends."""
    xs, ys = zip(*SIGMA_S)
    return np.interp(lam, xs, ys)


def check_ron():
    """The spectra above are the scene's: fail loudly if the .ron was edited."""
    text = open(os.path.join(HERE, "scenes", "cornell-medium.ron")).read()
    table = ", ".join(f"({w}, {v:.1f})" for w, v in SIGMA_S)
    want = [f"sigma_a: Constant({SIGMA_A})", f"sigma_s: Table([{table}])", f"HenyeyGreenstein(g: {G})",
            "Sphere(center: ({}, {}, {}), radius: {})".format(*CENTER, RADIUS)]
    for w in want:
        if w not in text:
            sys.exit(f"scenes/cornell-medium.ron: expected `{w}` (this script's copy of the medium)")


def spectrum(pairs):
    return ", ".join(f"{w:g}:{v:.6g}" for w, v in pairs)


def medium_xml():
    nodes = [360] + [w for w, _ in SIGMA_S] + [830]
    sigma_t = [(w, SIGMA_A + sigma_s(w)) for w in nodes]
    fine = np.arange(360, 831)
    albedo = [(w, sigma_s(w) / (SIGMA_A + sigma_s(w))) for w in fine]
    return f"""
    <!-- scenes/cornell-medium.ron's medium sphere: index-matched boundary (null bsdf), sigma_t =
         sigma_a + sigma_s and albedo = sigma_s / sigma_t of its sigma_a = {SIGMA_A}, sigma_s = Table{SIGMA_S} -->
    <shape type="sphere" id="medium_sphere">
        <point name="center" value="{CENTER[0]}, {CENTER[1]}, {CENTER[2]}"/>
        <float name="radius" value="{RADIUS}"/>
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior">
            <spectrum name="sigma_t" value="{spectrum(sigma_t)}"/>
            <spectrum name="albedo" value="{spectrum(albedo)}"/>
            <float name="scale" value="1"/>
            <phase type="hg">
                <float name="g" value="{G}"/>
            </phase>
        </medium>
    </shape>
"""


def write_xml(path, with_medium, integrator):
    text = open(os.path.join(HARNESS, "scenes", "cornell.xml")).read()
    text, n = re.subn(r'<integrator type="path">', f'<integrator type="{integrator}">', text)
    assert n == 1, "the harness's cornell.xml has no path integrator to replace"
    if with_medium:
        text = text.replace("</scene>", medium_xml() + "</scene>")
    with open(path, "w") as f:
        f.write(text)


def load(path):
    import mitsuba as mi
    a = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False))
    return a[:, :, :3].astype(np.float64)


def render_all(a, scene, out):
    """Renders SEEDS images per renderer; returns {renderer: (images, seconds per image)}."""
    ron = os.path.join(HERE, "scenes", "cornell-medium.ron" if scene == "medium" else "cornell-lambert.ron")
    xml = os.path.join(out, f"cornell-{scene}.xml")
    write_xml(xml, scene == "medium", a.integrator)
    times = {"mitsuba": [], "rust-v": []}
    for k in range(a.seeds):
        seed = a.seed0 + k
        base = os.path.join(out, f"{scene}-mitsuba-s{seed}")
        if not a.compare_only and not os.path.exists(base + ".json"):
            print(f"# {time.strftime('%H:%M:%S')} Mitsuba {a.variant} {a.integrator} {scene} seed {seed} "
                  f"{a.mitsuba_spp} spp", file=sys.stderr, flush=True)
            subprocess.run([sys.executable, os.path.join(HARNESS, "render.py"), xml, "--variant", a.variant,
                            "--spp", str(a.mitsuba_spp), "--seed", str(seed), "--res", str(RES),
                            "--max-depth", "8", "--warmup", "--out", base], check=True, stdout=sys.stderr)
        info = json.load(open(base + ".json"))
        if info["spp"] != a.mitsuba_spp:
            sys.exit(f"{base}.json: {info['spp']} spp, not --mitsuba-spp {a.mitsuba_spp} (another --out?)")
        times["mitsuba"].append(info["render_s"])
        exr = os.path.join(out, f"{scene}-rustv-s{seed}.exr")
        if not a.compare_only and not os.path.exists(exr + ".log"):
            print(f"# {time.strftime('%H:%M:%S')} rust-v {a.rustv_integrator} {scene} seed {seed} "
                  f"{a.rustv_spp} spp", file=sys.stderr, flush=True)
            r = subprocess.run([a.bin, "render", ron, "--spp", str(a.rustv_spp), "--seed", str(seed),
                                "--width", str(RES), "--height", str(RES),
                                "--integrator", a.rustv_integrator, "-o", exr],
                               check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            with open(exr + ".log", "w") as f:
                f.write(r.stderr)
        summary = re.findall(r"\(([0-9]+) passes in ([0-9.]+) s, ", open(exr + ".log").read())
        if not summary or int(summary[-1][0]) != a.rustv_spp:
            sys.exit(f"{exr}.log: not a {a.rustv_spp}-spp render (another --out?)")
        times["rust-v"].append(float(summary[-1][1]))
    imgs = {"mitsuba": [load(os.path.join(out, f"{scene}-mitsuba-s{a.seed0 + k}.exr")) for k in range(a.seeds)],
            "rust-v": [load(os.path.join(out, f"{scene}-rustv-s{a.seed0 + k}.exr")) for k in range(a.seeds)]}
    return {r: (np.stack(imgs[r]), times[r]) for r in imgs}


T = np.tan(np.radians(22.5))
EYE = np.array([0.0, 1.0, 3.5])


def project(p):
    d = np.asarray(p, float) - EYE
    return RES / 2 * (1 + d[0] / -d[2] / T), RES / 2 * (1 - d[1] / -d[2] / T)


def named_regions(scene):
    """(name, pixels, mask): squares around projected points, clear of edges; for the medium, also
    the sphere's disk (the pixels whose centre ray passes within 0.85 radii of its centre)."""
    pts = [("back wall", (0.0, 1.3, -1.0), 6), ("ceiling", (0.2, 2.0, 0.3), 4), ("floor, right front", (0.5, 0.0, 0.6), 4),
           ("red wall (left)", (-1.0, 1.0, 0.0), 4), ("green wall (right)", (1.0, 1.0, 0.0), 4),
           ("light", (-0.6, 1.7, -0.2), 2), ("blue sphere", (0.3, 0.35, 0.15), 4)]
    if scene == "medium":
        c = np.array(CENTER)
        # The light (-0.6, 1.7, -0.4) through the sphere's centre onto the floor: the middle of its shadow.
        lp = np.array([-0.6, 1.7, -0.4])
        shadow = lp + (c - lp) * (lp[1] / (lp[1] - c[1]))
        pts += [("medium sphere, centre", tuple(c), 6), ("medium sphere, upper rim", (c[0], c[1] + 0.3, c[2] + 0.25), 2),
                ("medium sphere, lower left", (c[0] - 0.22, c[1] - 0.2, c[2] + 0.25), 2),
                ("floor in the sphere's shadow", tuple(shadow), 3), ("floor before the sphere", (-0.4, 0.0, 0.85), 3)]
    out = []
    for name, p, h in pts:
        x, y = project(p)
        x, y = int(x), int(y)
        mask = np.zeros((RES, RES), bool)
        mask[y - h:y + h, x - h:x + h] = True
        out.append((name, f"x {x - h}-{x + h}, y {y - h}-{y + h}", mask))
    if scene == "medium":
        # Camera rays through pixel centres (the camera looks along -z with +y up).
        py, px = np.mgrid[0:RES, 0:RES] + 0.5
        d = np.stack([(2 * px / RES - 1) * T, (1 - 2 * py / RES) * T, -np.ones_like(px)], axis=-1)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        oc = np.array(CENTER) - EYE
        miss = np.linalg.norm(oc - (d @ oc)[..., None] * d, axis=-1)
        mask = miss < 0.85 * RADIUS
        out.append(("medium sphere, disk", f"{mask.sum()} pixels", mask))
    return out


def stats(stack, mask):
    """Region mean per channel and its standard error from the per-pixel spread across seeds."""
    reg = stack[:, mask, :]  # seeds x pixels x channels
    k, npix = reg.shape[0], reg.shape[1]
    mean = reg.mean(axis=(0, 1))
    var = reg.var(axis=0, ddof=1)  # per pixel, per channel, across seeds
    se = np.sqrt(var.sum(axis=0) / k) / npix
    return mean, se


def block(x0, y0):
    mask = np.zeros((RES, RES), bool)
    mask[y0:y0 + 16, x0:x0 + 16] = True
    return mask


def compare(scene, res, a):
    (rs, rt), (ms, mt) = res["rust-v"], res["mitsuba"]
    lines = [f"**{scene}** ({RES}x{RES}; rust-v `{a.rustv_integrator}` {a.seeds} x {a.rustv_spp} spp, "
             f"{np.mean(rt):.1f} s each; Mitsuba `{a.variant}` `{a.integrator}` {a.seeds} x {a.mitsuba_spp} spp, "
             f"{np.mean(mt):.1f} s each)", "",
             "| region | pixels | ch | rust-v | Mitsuba | difference | noise (1 se) | z |", "|---|---|---|---|---|---|---|---|"]
    worst = 0.0
    for name, pixels, mask in named_regions(scene):
        mr, sr = stats(rs, mask)
        mm, sm = stats(ms, mask)
        for c, ch in enumerate("RGB"):
            se = np.hypot(sr[c], sm[c])
            z = (mr[c] - mm[c]) / se
            worst = max(worst, abs(z))
            lines.append(f"| {name if c == 0 else ''} | {pixels if c == 0 else ''} | {ch} | "
                         f"{mr[c]:.4f} | {mm[c]:.4f} | {100 * (mr[c] / mm[c] - 1):+.2f}% | {100 * se / mm[c]:.2f}% | "
                         f"{z:+.1f} |")
    mr, mm = rs.mean(axis=(0, 1, 2)), ms.mean(axis=(0, 1, 2))
    lines.append("| whole image | | RGB | " + ", ".join(f"{v:.4f}" for v in mr) + " | " +
                 ", ".join(f"{v:.4f}" for v in mm) + " | " +
                 ", ".join(f"{100 * (p / q - 1):+.2f}%" for p, q in zip(mr, mm)) + " | | |")
    # 8x8 blocks of 16x16 pixels.
    zs, big = [], []
    for by in range(8):
        for bx in range(8):
            x0, y0 = 16 * bx, 16 * by
            br, sr = stats(rs, block(x0, y0))
            bm, sm = stats(ms, block(x0, y0))
            z = (br - bm) / np.hypot(sr, sm)
            zs.extend(z)
            big += [f"x {x0}-{x0 + 16} y {y0}-{y0 + 16} {ch}: {100 * (br[c] / bm[c] - 1):+.2f}% "
                    f"± {100 * np.hypot(sr[c], sm[c]) / bm[c]:.2f}% (z {z[c]:+.1f})"
                    for c, ch in enumerate("RGB") if abs(z[c]) > 3]
    zs = np.array(zs)
    lines += ["", f"8x8 blocks of 16x16 pixels, 3 channels (192 z): mean z {zs.mean():+.2f}, rms z {np.sqrt((zs ** 2).mean()):.2f} "
              f"(1 if within noise), largest |z| {np.abs(zs).max():.1f}, |z| > 3: {(np.abs(zs) > 3).sum()} "
              f"(expected about {192 * 0.0027:.1f}); largest |z| in the named regions {worst:.1f}."]
    lines += [f"- {b}" for b in big] + [""]
    return "\n".join(lines)


def effect(results, a):
    """What the medium changes, medium minus plain per seed, compared between the renderers: the
    two scenes share everything else, so a difference common to both (the colour integral) cancels."""
    lines = ["**The medium's effect** (medium minus plain, per seed; the regions the sphere changes)", "",
             "| region | ch | rust-v | Mitsuba | difference | noise (1 se) | z |", "|---|---|---|---|---|---|---|"]
    diff = {r: results["medium"][r][0] - results["plain"][r][0] for r in ("rust-v", "mitsuba")}
    plain_names = {n for n, *_ in named_regions("plain")}
    for name, _, mask in named_regions("medium"):
        if name in plain_names:
            continue
        mr, sr = stats(diff["rust-v"], mask)
        mm, sm = stats(diff["mitsuba"], mask)
        for c, ch in enumerate("RGB"):
            se = np.hypot(sr[c], sm[c])
            lines.append(f"| {name if c == 0 else ''} | {ch} | {mr[c]:+.4f} | {mm[c]:+.4f} | {mr[c] - mm[c]:+.4f} | "
                         f"{se:.4f} | {(mr[c] - mm[c]) / se:+.1f} |")
    return "\n".join(lines) + "\n"


def speed(a, res):
    """Time to equal error on the medium scene: per round, Mitsuba (`volpath` and `volpathmis`) at
    64 spp against Mitsuba's reference (the mean of the accuracy run's images), and rust-v at
    increasing spp until its linear MSE against its own reference is at most the better
    integrator's; rust-v's time is its spp times its mean time per spp over the round's renders."""
    import math
    refs = {}
    for r in ("mitsuba", "rust-v"):
        refs[r] = res[r][0].mean(axis=0)
    ron = os.path.join(HERE, "scenes", "cornell-medium.ron")

    def mse(img, r):
        return float(((img - refs[r]) ** 2).mean())

    def rustv(n, seed):
        exr = os.path.join(a.out, f"speed-rustv-{n}-s{seed}.exr")
        r = subprocess.run([a.bin, "render", ron, "--spp", str(n), "--seed", str(seed), "--width", str(RES),
                            "--height", str(RES), "--integrator", a.rustv_integrator, "-o", exr],
                           check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        return float(re.findall(r" in ([0-9.]+) s, ", r.stderr)[-1]), mse(load(exr), "rust-v")

    rows = []
    for k in range(a.speed):
        seed = 1000 + k  # not one of the references' seeds
        m = {}
        for integ in ("volpath", "volpathmis"):
            xml = os.path.join(a.out, f"cornell-medium-{integ}.xml")
            write_xml(xml, True, integ)
            base = os.path.join(a.out, f"speed-{integ}-s{seed}")
            subprocess.run([sys.executable, os.path.join(HARNESS, "render.py"), xml, "--variant", a.variant,
                            "--spp", "64", "--seed", str(seed), "--res", str(RES), "--max-depth", "8", "--warmup",
                            "--out", base], check=True, stdout=subprocess.DEVNULL, stderr=sys.stderr)
            m[integ] = (json.load(open(base + ".json"))["render_s"], mse(load(base + ".exr"), "mitsuba"))
        best = min(m, key=lambda i: m[i][0] * m[i][1])  # the lower time x error
        target = m[best][1]
        tot_t, tot_n = 0.0, 0
        n = 16
        t, e = rustv(n, seed)
        tot_t, tot_n = tot_t + t, tot_n + n
        n = max(1, math.ceil(n * e / target))
        t, e = rustv(n, seed)
        tot_t, tot_n = tot_t + t, tot_n + n
        if e > target:
            guess = n
            while e > target and n < 4 * guess:
                n = max(n + 1, math.ceil(n * 1.05))
                t, e = rustv(n, seed)
                tot_t, tot_n = tot_t + t, tot_n + n
        else:
            while n > 1:
                p = max(1, math.floor(n / 1.05)) if n > 20 else n - 1
                t2, e2 = rustv(p, seed)
                tot_t, tot_n = tot_t + t2, tot_n + p
                if e2 > target:
                    break
                n, e = p, e2
        rt = n * tot_t / tot_n
        print(f"# speed round {k + 1}: volpath {m['volpath']}, volpathmis {m['volpathmis']}, rust-v {n} spp "
              f"{rt:.2f} s MSE {e:.4g}", file=sys.stderr, flush=True)
        rows.append((seed, m, best, n, rt, e))
    lines = ["**Time to equal error, medium scene** (128x128; Mitsuba `llvm_ad_spectral` at 64 spp against "
             f"the mean of its {a.seeds} x {a.mitsuba_spp}-spp images; rust-v `{a.rustv_integrator}` against the "
             f"mean of its {a.seeds} x {a.rustv_spp}-spp images)", "",
             "| round (seed) | volpath: time (s), MSE | volpathmis: time (s), MSE | rust-v spp | rust-v time (s) | "
             "its MSE | rust-v / better Mitsuba |", "|---|---|---|---|---|---|---|"]
    ratios = []
    for seed, m, best, n, rt, e in rows:
        ratios.append(rt / m[best][0])
        lines.append(f"| {seed} | {m['volpath'][0]:.2f}, {m['volpath'][1]:.4g} | {m['volpathmis'][0]:.2f}, "
                     f"{m['volpathmis'][1]:.4g} | {n} | {rt:.2f} | {e:.4g} | {ratios[-1]:.2f} ({best}) |")
    ratios.sort()
    lines += ["", f"Median time ratio rust-v / Mitsuba: **{ratios[len(ratios) // 2]:.2f}x**.", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(HERE, "target", "release", "rust-v"))
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--seed0", type=int, default=1)
    ap.add_argument("--mitsuba-spp", type=int, default=2048)
    ap.add_argument("--rustv-spp", type=int, default=2048)
    ap.add_argument("--rustv-integrator", default="path")
    ap.add_argument("--scenes", default="medium,plain")
    ap.add_argument("--variant", default="llvm_ad_spectral")
    ap.add_argument("--integrator", default="volpath")
    ap.add_argument("--out", default="/tmp/peer-media")
    ap.add_argument("--compare-only", action="store_true")
    ap.add_argument("--speed", type=int, default=0, metavar="ROUNDS",
                    help="then time to equal error on the medium scene, ROUNDS rounds (references: the images above)")
    a = ap.parse_args()
    check_ron()
    os.makedirs(a.out, exist_ok=True)
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    print(f"rust-v vs Mitsuba {mi.__version__}, {os.cpu_count()} CPUs, {time.strftime('%Y-%m-%dT%H:%M:%S%z')}, "
          f"loadavg {open('/proc/loadavg').read().split()[:3]}\n")
    results = {}
    for scene in a.scenes.split(","):
        results[scene] = render_all(a, scene, a.out)
        print(compare(scene, results[scene], a), flush=True)
    if "medium" in results and "plain" in results:
        print(effect(results, a), flush=True)
    if a.speed and "medium" in results:
        print(speed(a, results["medium"]), flush=True)
    print(f"loadavg after {open('/proc/loadavg').read().split()[:3]}")


if __name__ == "__main__":
    main()
