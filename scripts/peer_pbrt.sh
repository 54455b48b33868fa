#!/usr/bin/env bash
# Renders a set of pbrt-v4 scene files with pbrt-v4 itself and with rust-v, then prints
# one table row per scene: mean luminance of each, their relative difference (rust-v's
# `compare`), and the worst of a REGIONS x REGIONS grid of regions with its noise.
#
#   scripts/peer_pbrt.sh PBRT_BINARY [OUTDIR]
#
# PBRT_BINARY is a CPU build of pbrt-v4 made outside the repository (nothing here
# builds it; docs/accuracy.md "Against pbrt-v4" says how it was built). Environment:
#   SPP=1024        samples per pixel for both renderers
#   SEED=7          pbrt's --seed (rust-v uses its own default seed)
#   REGIONS=4       the region grid per image side
#   RUSTV=target/release/rust-v
#   PBRT_SCENES=../shared/pbrt-v4-scenes   a copy of the public pbrt-v4-scenes files
#                   (see tests/data/pbrt/README.md); scenes from it are skipped when absent
#   SCENES="cornell glass gold coated envlight medium killeroo-simple"   a subset
#   REUSE=1         keep the images already in OUTDIR (only the table is made again)
# Needs python3 with numpy and OpenEXR (PyPI) for the region table.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
pbrt=${1:?usage: scripts/peer_pbrt.sh PBRT_BINARY [OUTDIR]}
out=${2:-/tmp/peer_pbrt}
spp=${SPP:-1024}
seed=${SEED:-7}
regions=${REGIONS:-4}
rustv=${RUSTV:-$here/target/release/rust-v}
real=${PBRT_SCENES:-$here/../shared/pbrt-v4-scenes}
scenes=${SCENES:-cornell glass gold coated envlight medium killeroo-simple}
[ -x "$pbrt" ] || { echo "peer_pbrt.sh: $pbrt is not an executable pbrt-v4 binary" >&2; exit 1; }
[ -x "$rustv" ] || { echo "peer_pbrt.sh: $rustv is missing: run cargo build --release" >&2; exit 1; }
mkdir -p "$out/pbrt" "$out/rust-v" "$out/scenes"

# The scene file for a name, with the resolution both renderers use (pbrt has no flag
# for it: a real file is copied with its Film resolution changed, beside a link to its
# folder's geometry so that Include finds it).
scene_file() {
  case $1 in
    cornell)
      mkdir -p "$out/scenes/cornell"
      cp "$here/scenes/pbrt/box.pbrt" "$out/scenes/cornell/"
      sed -e 's/"integer \([xy]\)resolution" \[ 256 \]/"integer \1resolution" [ 128 ]/g' \
        "$here/scenes/pbrt/cornell.pbrt" > "$out/scenes/cornell/cornell.pbrt"
      echo "$out/scenes/cornell/cornell.pbrt" ;;
    killeroo-simple)
      [ -f "$real/killeroos/killeroo-simple.pbrt" ] || return 1
      mkdir -p "$out/scenes/killeroos"
      ln -sfn "$real/killeroos/geometry" "$out/scenes/killeroos/geometry"
      sed -e 's/"integer \([xy]\)resolution" \[ 700 \]/"integer \1resolution" [ 175 ]/' \
        "$real/killeroos/killeroo-simple.pbrt" > "$out/scenes/killeroos/killeroo-simple.pbrt"
      echo "$out/scenes/killeroos/killeroo-simple.pbrt" ;;
    *) echo "$here/tests/data/pbrt/peer/$1.pbrt" ;;
  esac
}

rows=()
for name in $scenes; do
  if ! f=$(scene_file "$name"); then
    echo "skipped $name: not found under $real" >&2
    continue
  fi
  a="$out/rust-v/$name.exr" b="$out/pbrt/$name.exr"
  if [ -n "${REUSE:-}" ] && [ -f "$a" ] && [ -f "$b" ]; then
    rel=$("$rustv" compare "$a" "$b" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["rel_err_luminance"])')
    rows+=("$name $a $b $rel 0 0")
    continue
  fi
  t0=$(date +%s.%N)
  "$pbrt" --spp "$spp" --seed "$seed" --outfile "$b" "$f" > "$out/pbrt/$name.log" 2>&1 ||
    { echo "pbrt failed on $name: see $out/pbrt/$name.log" >&2; exit 1; }
  t1=$(date +%s.%N)
  "$rustv" render "$f" -o "$a" --spp "$spp" -q 2> "$out/rust-v/$name.log" ||
    { echo "rust-v failed on $name: see $out/rust-v/$name.log" >&2; exit 1; }
  t2=$(date +%s.%N)
  rel=$("$rustv" compare "$a" "$b" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["rel_err_luminance"])')
  rows+=("$name $a $b $rel $(echo "$t1 - $t0" | bc) $(echo "$t2 - $t1" | bc)")
done

python3 - "$regions" "$spp" "${rows[@]}" <<'EOF'
import sys

import numpy as np
import OpenEXR


def lum(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            rgb = np.asarray(ch["RGB"].pixels, dtype=np.float64)
        else:
            rgb = np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


n, spp = int(sys.argv[1]), sys.argv[2]
print(f"spp {spp}, {n}x{n} regions; region difference = (rust-v - pbrt) / pbrt of the region's mean")
print("luminance, se = standard error of that difference from the spread of its pixels' differences")
print("(image structure included, so it overstates the noise); regions darker than 2% of the median")
print("region are left out; the worst region is the largest |difference| among those with se < 2%.")
print()
print("| scene | mean Y pbrt | mean Y rust-v | rel. err. Y (compare) | worst region (row, col) | its difference | its se | regions beyond 3 se | time pbrt / rust-v (s) |")
print("|---|---|---|---|---|---|---|---|---|")
for row in sys.argv[3:]:
    name, a, b, rel, tp, tr = row.split()
    ya, yb = lum(a), lum(b)
    h, w = yb.shape
    worst, beyond, counted = None, 0, 0
    cells = [(slice(i * h // n, (i + 1) * h // n), slice(j * w // n, (j + 1) * w // n), i, j) for i in range(n) for j in range(n)]
    floor = 0.02 * np.median([yb[r, c].mean() for r, c, _, _ in cells])
    for r, c, i, j in cells:
        ra, rb = ya[r, c], yb[r, c]
        mb = rb.mean()
        if mb < floor:
            continue
        d = ra - rb
        diff = d.mean() / mb
        se = d.std(ddof=1) / np.sqrt(d.size) / mb
        counted += 1
        beyond += abs(diff) > 3 * se
        if se < 0.02 and (worst is None or abs(diff) > abs(worst[2])):
            worst = (i, j, diff, se)
    i, j, diff, se = worst
    times = f"{float(tp):.0f} / {float(tr):.0f}" if float(tp) > 0 else "-"
    print(f"| {name} | {yb.mean():.4f} | {ya.mean():.4f} | {float(rel):.2%} | ({i}, {j}) | {diff:+.2%} | {se:.2%} | {beyond} of {counted} | {times} |")
EOF
