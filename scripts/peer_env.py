#!/usr/bin/env python3
"""rust-v against Mitsuba 3 on scenes/environment.ron: time to equal error (issue 35).

The scene (three spheres on a checkerboard floor under scenes/textures/outdoor.exr) is
transcribed for Mitsuba here, with one change made on both sides: the glass has the constant
index 1.5168 (N-BK7 at 587.6 nm) instead of the dispersive N-BK7, which Mitsuba's `dielectric`
cannot take; rust-v renders a copy of the scene with `Dielectric(ior: Constant(1.5168))`. The rest:

* camera eye (0, 1.1, 4.2) looking at (0, 0.45, 0), vertical field of view 38°; 192x128 (the
  scene's 384x256 halved); rust-v max_bounces 8 = Mitsuba max_depth 9, both `rr_depth` 5;
* environment: Mitsuba `envmap` with the same EXR (rust-v's map orientation is Mitsuba's, no
  transform), scale 1;
* floor: the quad origin (-4, 0, 4), edges (8, 0, 0) and (0, 0, -8) is a Mitsuba `rectangle`
  whose local x, y run along the two edges: its uv (0..1 along each) is rust-v's quad u, v;
  rust-v's `Checkerboard(scale: 16)` has 16 squares per unit of u and v, `even` where
  floor(16u) + floor(16v) is even; Mitsuba's `checkerboard` has 2 squares per unit of its uv and
  `color0` where both halves agree, so its uv is scaled by 8 (`to_uv`) and color0 = even;
  the odd squares and the clay are `rgb` reflectances (Jakob-Hanika uplift on both sides);
* gold: `roughconductor` material="Au", GGX alpha 0.08 (rust-v's roughness is GGX alpha);
* glass: `dielectric` int_ior 1.5168, ext_ior 1 (Mitsuba's default outside is air, 1.000277).

Per round (seed), Mitsuba llvm_ad_spectral renders 64 spp; its linear MSE against Mitsuba's own
high-spp reference is the target; rust-v (`auto`) renders at increasing spp until its MSE against
rust-v's own high-spp reference is at most the target (each renderer against its own converged
image, so the small differences between the two models, also reported, do not count as error);
rust-v's time is its spp times its mean time per spp over the round's renders, as
scripts/peer_mitsuba.sh does. Run with the harness venv's python (scripts/peer_env.sh).

--white-floor instead checks the map's colour in both renderers against an independent truth
(a white floor under the map alone against the irradiance summed over the EXR's texels).
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import time

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from peer_media import HARNESS, HERE, load  # noqa: E402

W, H = 192, 128
IOR = 1.5168


def write_scene_files(out):
    exr = os.path.join(HERE, "scenes", "textures", "outdoor.exr")
    if not os.path.exists(exr):
        sys.exit(f"{exr}: missing; make it with `cargo run --release --example make_textures`")
    ron = open(os.path.join(HERE, "scenes", "environment.ron")).read()
    for old, new in [('Dielectric(ior: Named("N-BK7"))', f"Dielectric(ior: Constant({IOR}))"),
                     ('path: "textures/outdoor.exr"', f'path: "{exr}"')]:
        if old not in ron:
            sys.exit(f"scenes/environment.ron: expected `{old}` (this script's transcription is out of date)")
        ron = ron.replace(old, new)
    for want in ["eye: (0, 1.1, 4.2), look_at: (0, 0.45, 0), up: (0, 1, 0), fov_deg: 38", "max_bounces: 8",
                 'Conductor(metal: "Au", roughness: 0.08)', "Rgb(0.75, 0.35, 0.15)",
                 "Checkerboard(even: Constant(0.75), odd: Rgb(0.12, 0.14, 0.2), scale: 16)",
                 "Quad(origin: (-4, 0, 4), edge_u: (8, 0, 0), edge_v: (0, 0, -8))",
                 "Sphere(center: (-1.25, 0.5, 0), radius: 0.5), material: \"glass\"",
                 "Sphere(center: (0, 0.5, -0.4), radius: 0.5), material: \"gold\"",
                 "Sphere(center: (1.25, 0.5, 0), radius: 0.5), material: \"clay\""]:
        if want not in ron:
            sys.exit(f"scenes/environment.ron: expected `{want}` (this script's transcription is out of date)")
    ron_path = os.path.join(out, "environment-const.ron")
    open(ron_path, "w").write(ron)
    xml = f"""<?xml version="1.0" encoding="utf-8"?>
<!-- scenes/environment.ron for Mitsuba 3 (written by scripts/peer_env.py; glass at constant n {IOR}). -->
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <default name="res" value="{H}"/>
    <default name="max_depth" value="9"/>
    <integrator type="path">
        <integer name="max_depth" value="$max_depth"/>
        <integer name="rr_depth" value="5"/>
    </integrator>
    <sensor type="perspective">
        <string name="fov_axis" value="y"/>
        <float name="fov" value="38"/>
        <float name="near_clip" value="0.001"/>
        <float name="far_clip" value="1000"/>
        <transform name="to_world">
            <lookat origin="0, 1.1, 4.2" target="0, 0.45, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="{W}"/>
            <integer name="height" value="$res"/>
            <string name="pixel_format" value="rgb"/>
            <string name="component_format" value="float32"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="envmap">
        <string name="filename" value="{exr}"/>
        <float name="scale" value="1"/>
    </emitter>
    <shape type="rectangle">
        <!-- local x (-1..1) -> world x (-4..4) = edge_u, local y -> world z (4..-4) = edge_v, normal -> +y -->
        <transform name="to_world">
            <matrix value="4 0 0 0   0 0 1 0   0 -4 0 0   0 0 0 1"/>
        </transform>
        <bsdf type="diffuse">
            <texture name="reflectance" type="checkerboard">
                <rgb name="color0" value="0.75, 0.75, 0.75"/>
                <rgb name="color1" value="0.12, 0.14, 0.2"/>
                <transform name="to_uv"><scale x="8" y="8"/></transform>
            </texture>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" value="-1.25, 0.5, 0"/>
        <float name="radius" value="0.5"/>
        <bsdf type="dielectric">
            <float name="int_ior" value="{IOR}"/>
            <float name="ext_ior" value="1"/>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" value="0, 0.5, -0.4"/>
        <float name="radius" value="0.5"/>
        <bsdf type="roughconductor">
            <string name="material" value="Au"/>
            <string name="distribution" value="ggx"/>
            <float name="alpha" value="0.08"/>
        </bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" value="1.25, 0.5, 0"/>
        <float name="radius" value="0.5"/>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.75, 0.35, 0.15"/>
        </bsdf>
    </shape>
</scene>
"""
    xml_path = os.path.join(out, "environment.xml")
    open(xml_path, "w").write(xml)
    return ron_path, xml_path


def mse(a, b):
    return float(((load(a) - load(b)) ** 2).mean())


def mitsuba(xml, variant, spp, seed, out):
    base = os.path.join(out, f"m-{variant}-{spp}-s{seed}")
    cmd = [sys.executable, os.path.join(HARNESS, "render.py"), xml, "--variant", variant, "--spp", str(spp),
           "--seed", str(seed), "--warmup", "--out", base]
    subprocess.run(cmd, check=True, stdout=sys.stderr)
    return json.load(open(base + ".json"))["render_s"], base + ".exr"


# The sun's caustic on the floor left of the glass sphere (docs/performance.md, "Where the error is"):
# rows 70-91, columns 0-44 at 192x128.
CAUSTIC_ROWS, CAUSTIC_COLS = slice(70, 92), slice(0, 45)


def box_mse(a, b):
    """MSE within the caustic's box."""
    return float(((load(a) - load(b))[CAUSTIC_ROWS, CAUSTIC_COLS] ** 2).mean())


def rustv(binary, ron, spp, seed, out, integrator="auto"):
    exr = os.path.join(out, f"r-{integrator}-{spp}-s{seed}.exr")
    r = subprocess.run([binary, "render", ron, "--spp", str(spp), "--seed", str(seed), "--width", str(W),
                        "--height", str(H), "--integrator", integrator, "-o", exr], check=True,
                       stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True)
    t = re.findall(r" in ([0-9.]+) s, ", r.stderr)
    return float(t[-1]), exr


def white_floor(binary, out):
    """The map's colour, against an independent truth: a flat white floor (0.75) under the map alone,
    direct light only, seen from above, renders 0.75 E / pi, E the irradiance summed over the
    map's texels (piecewise constant; the bilinear filter changes it by far less than 1%)."""
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    exr = os.path.join(HERE, "scenes", "textures", "outdoor.exr")
    lmap = np.array(mi.Bitmap(exr), dtype=np.float64)[:, :, :3]
    h, w, _ = lmap.shape
    theta = (np.arange(h) + 0.5) / h * np.pi
    dw = np.maximum(np.cos(theta), 0) * np.sin(theta) * (2 * np.pi / w) * (np.pi / h)
    expected = 0.75 * (lmap * dw[:, None, None]).sum(axis=(0, 1)) / np.pi
    ron = os.path.join(out, "white-floor.ron")
    open(ron, "w").write(f"""(
    camera: (eye: (0, 3, 0.01), look_at: (0, 0, 0), up: (0, 0, -1), fov_deg: 30),
    render: (width: 32, height: 32, spp: 256, seed: 0, max_bounces: 1),
    materials: {{ "white": Lambertian(reflectance: Constant(0.75)) }},
    objects: [ (shape: Quad(origin: (-4, 0, 4), edge_u: (8, 0, 0), edge_v: (0, 0, -8)), material: "white") ],
    environment: Image(path: "{exr}"),
)
""")
    xml = os.path.join(out, "white-floor.xml")
    open(xml, "w").write(f"""<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        <string name="fov_axis" value="y"/><float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 3, 0.01" target="0, 0, 0" up="0, 0, -1"/></transform>
        <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/>
            <string name="pixel_format" value="rgb"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="envmap"><string name="filename" value="{exr}"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><matrix value="4 0 0 0   0 0 1 0   0 -4 0 0   0 0 0 1"/></transform>
        <bsdf type="diffuse"><spectrum name="reflectance" value="0.75"/></bsdf>
    </shape>
</scene>
""")
    r = os.path.join(out, "white-floor-rustv.exr")
    subprocess.run([binary, "render", ron, "-o", r], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, m = mitsuba(xml, "llvm_ad_spectral", 1024, 3, out)
    print("White floor under the map alone, mean linear sRGB (R, G, B):\n")
    print("| | R | G | B |\n|---|---|---|---|")
    print("| expected, 0.75 E / pi from the texels | " + " | ".join(f"{v:.4f}" for v in expected) + " |")
    for name, path in [("rust-v, 256 spp", r), ("Mitsuba llvm_ad_spectral, 1024 spp", m)]:
        v = load(path).reshape(-1, 3).mean(axis=0)
        print(f"| {name} | " + " | ".join(f"{x:.4f} ({100 * (x / e - 1):+.1f}%)" for x, e in zip(v, expected)) + " |")
    # The sun seen directly (30° field of view towards it, +x and 35° up): its core and the texels
    # its bilinear filter blends with the sky, along the middle row.
    sun_dir = "0.819152, 0.573576, 0"
    ron = os.path.join(out, "sun.ron")
    open(ron, "w").write(f"""(
    camera: (eye: (0, 0, 0), look_at: ({sun_dir}), up: (0, 1, 0), fov_deg: 30),
    render: (width: 32, height: 32, spp: 64, seed: 0, max_bounces: 1),
    materials: {{ "black": Lambertian(reflectance: Constant(0)) }},
    objects: [ (shape: Sphere(center: (-50, -50, -50), radius: 0.01), material: "black") ],
    environment: Image(path: "{exr}"),
)
""")
    xml = os.path.join(out, "sun.xml")
    open(xml, "w").write(f"""<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        <string name="fov_axis" value="y"/><float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 0" target="{sun_dir}" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/>
            <string name="pixel_format" value="rgb"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="envmap"><string name="filename" value="{exr}"/></emitter>
</scene>
""")
    r = os.path.join(out, "sun-rustv.exr")
    subprocess.run([binary, "render", ron, "-o", r], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, m = mitsuba(xml, "llvm_ad_spectral", 256, 3, out)
    ri, mi_ = load(r), load(m)
    print("\nThe sun seen directly, 30° wide, the middle row (linear sRGB):\n")
    print("| pixel | rust-v | Mitsuba |\n|---|---|---|")
    for x in range(6, 27, 2):
        print(f"| {x} | " + " | ".join("(" + ", ".join(f"{c:.2f}" for c in img[16, x]) + ")" for img in (ri, mi_)) + " |")


def log(*a):
    print(f"# {time.strftime('%H:%M:%S')}", *a, file=sys.stderr, flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(HERE, "target", "release", "rust-v"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seed0", type=int, default=1)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_spectral")
    ap.add_argument("--integrator", default="auto",
                    help="rust-v's integrator for the timed renders (the reference is always auto's)")
    ap.add_argument("--out", default="/tmp/peer-env")
    ap.add_argument("--white-floor", action="store_true",
                    help="only the colour check: a white floor under the map, against the texels' irradiance")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.white_floor:
        white_floor(a.bin, a.out)
        return
    ron, xml = write_scene_files(a.out)
    import mitsuba as mi
    print(f"rust-v vs Mitsuba {mi.__version__} on scenes/environment.ron ({W}x{H}, glass n = {IOR}), "
          f"{os.cpu_count()} CPUs, {time.strftime('%Y-%m-%dT%H:%M:%S%z')}, "
          f"loadavg {' '.join(open('/proc/loadavg').read().split()[:3])}\n")
    mref = os.path.join(a.out, f"ref-mitsuba-{a.ref_spp}.exr")
    rref = os.path.join(a.out, f"ref-rustv-{a.ref_spp}.exr")
    if not os.path.exists(mref):
        log(f"Mitsuba reference, {a.ref_spp} spp")
        _, p = mitsuba(xml, a.variant, a.ref_spp, 1000000, a.out)
        os.replace(p, mref)
    if not os.path.exists(rref):
        log(f"rust-v reference, {a.ref_spp} spp")
        _, p = rustv(a.bin, ron, a.ref_spp, 1000000, a.out)
        os.replace(p, rref)
    rows = []
    for r in range(a.rounds):
        seed = a.seed0 + r
        lt, li = mitsuba(xml, a.variant, 64, seed, a.out)
        le = mse(li, mref)
        le_x = mse(li, rref)
        tot_t, tot_n = 0.0, 0
        n = 16
        rt, ri = rustv(a.bin, ron, n, seed, a.out, a.integrator)
        tot_t, tot_n = tot_t + rt, tot_n + n
        re_ = mse(ri, rref)
        log(f"round {r + 1}: Mitsuba 64 spp {lt:.2f} s, MSE {le:.4g} (against rust-v's reference {le_x:.4g}); "
            f"rust-v 16 spp {rt:.2f} s MSE {re_:.4g}")
        n = max(1, math.ceil(n * re_ / le))
        rt, ri = rustv(a.bin, ron, n, seed, a.out, a.integrator)
        tot_t, tot_n = tot_t + rt, tot_n + n
        re_ = mse(ri, rref)
        log(f"  rust-v {n} spp {rt:.2f} s MSE {re_:.4g}")
        if re_ > le:
            guess = n
            while re_ > le and n < 4 * guess:
                n = max(n + 1, math.ceil(n * 1.05))
                rt, ri = rustv(a.bin, ron, n, seed, a.out, a.integrator)
                tot_t, tot_n = tot_t + rt, tot_n + n
                re_ = mse(ri, rref)
                log(f"  rust-v {n} spp {rt:.2f} s MSE {re_:.4g}")
        else:
            while n > 1:
                m = max(1, math.floor(n / 1.05)) if n > 20 else n - 1
                pt, pi = rustv(a.bin, ron, m, seed, a.out, a.integrator)
                tot_t, tot_n = tot_t + pt, tot_n + m
                pe = mse(pi, rref)
                log(f"  rust-v {m} spp {pt:.2f} s MSE {pe:.4g}")
                if pe > le:
                    break
                n, re_, ri = m, pe, pi
        per = tot_t / tot_n
        rows.append((seed, lt, le, le_x, n, n * per, re_, box_mse(ri, rref), box_mse(li, mref)))
        log(f"  rust-v time to the error: {n} spp x {per:.5f} s = {n * per:.3f} s; ratio {n * per / lt:.3f}")
    print(f"rust-v: --integrator {a.integrator}\n")
    print("| round (seed) | Mitsuba 64 spp: time (s) | its MSE (own ref.) | caustic box | rust-v spp | rust-v time (s) | "
          "its MSE (own ref.) | caustic box | time ratio rust-v / Mitsuba |")
    print("|---|---|---|---|---|---|---|---|---|")
    for seed, lt, le, le_x, n, t, re_, rbox, mbox in rows:
        print(f"| {seed} | {lt:.2f} | {le:.4g} | {mbox:.4g} | {n} | {t:.2f} | {re_:.4g} | {rbox:.4g} | {t / lt:.2f} |")
    ratios = sorted(t / lt for _, lt, _, _, _, t, _, _, _ in rows)
    print(f"\nMedian time ratio rust-v / Mitsuba: **{ratios[len(ratios) // 2]:.2f}x**.")
    x = mse(rref, mref)
    print(f"\nThe two references against each other (model differences plus both references' noise): "
          f"MSE {x:.4g}; means rust-v {load(rref).mean(axis=(0, 1)).round(4).tolist()}, "
          f"Mitsuba {load(mref).mean(axis=(0, 1)).round(4).tolist()}.")
    print(f"\nloadavg after {' '.join(open('/proc/loadavg').read().split()[:3])}")


if __name__ == "__main__":
    main()
