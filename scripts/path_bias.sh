#!/usr/bin/env bash
# Measures the squared bias of the `path` integrator (every wavelength refracts
# like 589.3 nm) against the unbiased `auto`, and the error below which `auto`
# reaches an image sooner than `path`, without a converged reference.
#
#   scripts/path_bias.sh SCENE [SPP] [SIZE] [OUT]     (defaults: 1024 spp, 128x128, ./bias)
#
# Each method renders passes 0..SPP and SPP..2*SPP as separate parts (two
# independent halves, timed) and merges them; the two methods use different
# seeds, so all four halves are independent. With V the per-sample variance of
# a pixel (mean over pixels and channels), linear-sRGB MSEs give
#   D_pp = MSE(path half 1, path half 2)          = 2 V_path / SPP
#   D_aa = MSE(auto half 1, auto half 2)          = 2 V_auto / SPP
#   D_pa = MSE(path merged, auto merged)          = B + V_path/(2 SPP) + V_auto/(2 SPP)
# so B = D_pa - D_pp/4 - D_aa/4 is an unbiased estimate of path's squared bias
# (its standard error is about 1% of the subtracted terms at 128x128).
# With a = V and s = seconds per spp, the error (against the truth) after t
# seconds is a s / t for auto and B + a s / t for path; auto is sooner for every
# target below e* = B A / (A - P), A = a_auto s_auto, P = a_path s_path.
set -euo pipefail

SCENE="$1"
SPP="${2:-1024}"
SIZE="${3:-128}"
OUT="${4:-bias}"
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
REPO="$(dirname "$HERE")"
(cd "$REPO" && cargo build --release --quiet)
BIN="$REPO/target/release/rust-v"
mkdir -p "$OUT"
name="$(basename "$SCENE" .ron)"

# Different seeds: with the same seed both methods draw the same random numbers
# and trace the same paths until a path meets glass, so their noise correlates.
declare -A secs
declare -A seed=([path]=1 [auto]=2)
for m in path auto; do
    total=0
    for half in 1 2; do
        a=$(((half - 1) * SPP))
        b=$((half * SPP))
        # The render's own time (passes only: no loading, no file writes).
        t=$("$BIN" render "$SCENE" --integrator "$m" --seed "${seed[$m]}" --width "$SIZE" --height "$SIZE" --passes "$a..$b" \
            -o "$OUT/$name-$m-$half.exr" --checkpoint "$OUT/$name-$m-$half.ckpt" 2>&1 |
            tr '\r' '\n' | grep -o 'passes in [0-9.]* s' | grep -o '[0-9.]*')
        total=$(python3 -c "print($total + $t)")
    done
    secs[$m]=$total
    "$BIN" merge "$OUT/$name-$m-1.ckpt" "$OUT/$name-$m-2.ckpt" -o "$OUT/$name-$m.exr" 2>/dev/null
done

mse() { "$BIN" compare --json "$1" "$2" | python3 -c "import json,sys; print(json.load(sys.stdin)['mse_lin'])"; }
dpp=$(mse "$OUT/$name-path-1.exr" "$OUT/$name-path-2.exr")
daa=$(mse "$OUT/$name-auto-1.exr" "$OUT/$name-auto-2.exr")
dpa=$(mse "$OUT/$name-path.exr" "$OUT/$name-auto.exr")

python3 - "$name" "$SPP" "$SIZE" "$dpp" "$daa" "$dpa" "${secs[path]}" "${secs[auto]}" <<'EOF'
import sys
name, spp, size = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
dpp, daa, dpa, tp, ta = map(float, sys.argv[4:9])
vp, va = dpp * spp / 2, daa * spp / 2
b = dpa - dpp / 4 - daa / 4
sp, sa = tp / (2 * spp), ta / (2 * spp)
A, P = va * sa, vp * sp
print(f"{name} at {size}x{size}, 2 x {spp} spp per method (linear sRGB MSE):")
print(f"  D_pp {dpp:.4e}  D_aa {daa:.4e}  D_pa {dpa:.4e}")
print(f"  per-sample variance: path {vp:.4g}, auto {va:.4g}; seconds per spp: path {sp:.4g}, auto {sa:.4g}")
print(f"  a x s (error x seconds): path {P:.4g}, auto {A:.4g} (auto/path {A / P:.2f})")
print(f"  path squared bias B = {b:.4e} (subtracted noise terms {dpp / 4 + daa / 4:.3e})")
if b <= 0:
    print("  no measurable bias: path is never worse")
elif A <= P:
    print("  auto is sooner at every error")
else:
    e = b * A / (A - P)
    print(f"  auto is sooner below an error of {e:.3e}: {A / e:.0f} s, {va / e:.0f} spp of auto at this size (path never gets below {b:.3e})")
EOF
