#!/usr/bin/env bash
# rust-v against Mitsuba 3 in one sitting (issue 18's "Measure and report"):
#
# 1. Canonical Cornell box (scenes/cornell-lambert.ron, 256x256): per round, Mitsuba
#    llvm_ad_spectral and scalar_spectral at 64 spp, then rust-v at increasing spp until
#    its linear MSE against the harness's reference (refs/cornell.exr) is at most that
#    round's llvm 64-spp MSE. Reports each side's render time and the time-to-equal-error
#    ratios rust-v / Mitsuba (medians over rounds).
# 2. glass-spheres (SCENE-SPEC.md §5: three smooth glass spheres, constant IOR 1.5, no
#    blue sphere, max_depth 10 = 9 bounces; rust-v's scene is written from the spec into a
#    temporary file, materials-trio.ron's box with three Dielectric(ior: Constant(1.5))):
#    per round, Mitsuba llvm at 64 spp, then rust-v with that render's time as its budget
#    (`--time`); reports both errors and their ratio (error at equal time).
#
# Rounds are interleaved (Mitsuba, then rust-v, round after round) so both see the same
# machine load; every side uses all cores (2 threads here). Times are render times as each
# renderer reports them (Mitsuba: render.py's render_s with the JIT warmed up; rust-v: the
# "N passes in T s" of its summary), scene loading excluded on both sides. rust-v's time to
# the error is its spp times its mean time per spp over the round's renders (16 spp, the
# guess, the steps), which is less noisy than the one render at that spp.
#
#   scripts/peer_mitsuba.sh [BINARY]        # default target/release/rust-v
#   ROUNDS=3 SEED0=1 scripts/peer_mitsuba.sh
#
# Needs the harness ../shared/peers/mitsuba and its venv (bash ../shared/peers/mitsuba/setup.sh).
# glass-spheres needs a reference: $GLASS_REF, else refs/glass-spheres.exr or
# $PEERS_DIR/out/ref/glass-spheres.exr of the harness; when none exists it is rendered once
# with Mitsuba llvm_ad_spectral at GLASS_REF_SPP (default 4096; the harness's own reference
# uses 16384) and kept in $PEERS_DIR/out/ref/. A reference of R spp adds its own error,
# about MSE(64 spp) * 64 / R, to every measured error: 1.6% at 4096 spp.
# Prints markdown tables; the raw per-round numbers go to stderr.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$here/target/release/rust-v}")
harness=$(realpath "${HARNESS:-$here/../shared/peers/mitsuba}")
export PEERS_DIR=${PEERS_DIR:-$HOME/.cache/peers}
py=${MITSUBA_VENV:-$PEERS_DIR/mitsuba-venv}/bin/python
rounds=${ROUNDS:-3}
seed0=${SEED0:-1}
glass_ref_spp=${GLASS_REF_SPP:-4096}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
[ -x "$py" ] || { echo "no Mitsuba venv at $py: run bash $harness/setup.sh" >&2; exit 1; }
[ -x "$bin" ] || { echo "no rust-v binary at $bin: cargo build --release" >&2; exit 1; }

log() { echo "$*" >&2; }
# A render runs in a process substitution, where `exit` cannot stop this script: check its output.
need() { [ -n "${1:-}" ] && [ -n "${2:-}" ] || { echo "a render failed (see above)" >&2; exit 1; }; }
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
# The linear MSE of an image against a reference (rust-v compare = the harness's mse_lin).
mse() { "$bin" compare --json "$1" "$2" | python3 -c 'import json,sys; print(json.load(sys.stdin)["mse_lin"])'; }
# Mitsuba: render SCENE VARIANT SPP SEED -> prints "seconds image.exr".
mitsuba() {
  local out="$dir/m-$1-$2-$3-$4"
  "$py" "$harness/render.py" "$1" --variant "$2" --spp "$3" --seed "$4" --warmup --out "$out" >/dev/null 2>"$dir/m.err" \
    || { cat "$dir/m.err" >&2; exit 1; }
  echo "$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["render_s"])' "$out.json") $out.exr"
}
# rust-v: render SCENE SPP SEED [ARGS...] -> prints "seconds image.exr" (render time from the summary).
rustv() {
  local scene=$1 spp=$2 seed=$3 out="$dir/r-$(basename "$1" .ron)-$2-$3.exr"
  shift 3
  "$bin" render "$scene" --spp "$spp" --seed "$seed" -o "$out" "$@" 2>"$dir/r.err" >/dev/null \
    || { cat "$dir/r.err" >&2; exit 1; }
  local t
  t=$(sed -n 's/.* in \([0-9.]*\) s, .*/\1/p' "$dir/r.err" | tail -1)
  echo "$t $out"
}

cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')
echo "rust-v vs Mitsuba 3 ($("$py" -c 'import mitsuba; print(mitsuba.__version__)' 2>/dev/null || echo '?')): $cpu, $(nproc) CPUs, $(date -u +%FT%TZ)"
echo "loadavg before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo

# ---- 1. Cornell: time to equal error ----
cref=$harness/refs/cornell.exr
c_llvm_t=() c_llvm_e=() c_scal_t=() c_scal_e=() c_r_t=() c_r_e=() c_r_spp=() c_ratio_llvm=() c_ratio_scal=()
for r in $(seq "$rounds"); do
  seed=$((seed0 + r - 1))
  read -r lt li < <(mitsuba cornell llvm_ad_spectral 64 "$seed")
  need "$lt" "$li"
  le=$(mse "$li" "$cref")
  read -r st si < <(mitsuba cornell scalar_spectral 64 "$seed")
  need "$st" "$si"
  se=$(mse "$si" "$cref")
  # rust-v: a probe at 16 spp, a guess from MSE ~ 1/spp, then one pass up (or down) at a time
  # to the fewest passes that reach the target. Passes are nested (pass k of a pixel draws the
  # same numbers at any spp), so the error sequence is one converging render's.
  n=16 tot_t=0 tot_n=0
  read -r rt ri < <(rustv "$here/scenes/cornell-lambert.ron" "$n" "$seed")
  need "$rt" "$ri"
  tot_t=$(echo "$tot_t + $rt" | bc -l) tot_n=$((tot_n + n))
  re=$(mse "$ri" "$cref")
  log "cornell round $r: llvm $lt s $le, scalar $st s $se; rust-v $n spp $rt s $re"
  guess=$(python3 -c "import math,sys; print(max(1, math.ceil(int(sys.argv[1]) * float(sys.argv[2]) / float(sys.argv[3]))))" "$n" "$re" "$le")
  n=$guess
  read -r rt ri < <(rustv "$here/scenes/cornell-lambert.ron" "$n" "$seed")
  need "$rt" "$ri"
  tot_t=$(echo "$tot_t + $rt" | bc -l) tot_n=$((tot_n + n))
  re=$(mse "$ri" "$cref")
  log "  rust-v $n spp: $rt s, MSE $re"
  if [ "$(echo "$re > $le" | bc -l)" = 1 ]; then
    while [ "$(echo "$re > $le" | bc -l)" = 1 ] && [ "$n" -lt $((4 * guess)) ]; do
      n=$((n + 1))
      read -r rt ri < <(rustv "$here/scenes/cornell-lambert.ron" "$n" "$seed")
      need "$rt" "$ri"
      tot_t=$(echo "$tot_t + $rt" | bc -l) tot_n=$((tot_n + n))
      re=$(mse "$ri" "$cref")
      log "  rust-v $n spp: $rt s, MSE $re"
    done
  else
    while [ "$n" -gt 1 ]; do
      read -r pt pi < <(rustv "$here/scenes/cornell-lambert.ron" $((n - 1)) "$seed")
      need "$pt" "$pi"
      tot_t=$(echo "$tot_t + $pt" | bc -l) tot_n=$((tot_n + n - 1))
      pe=$(mse "$pi" "$cref")
      log "  rust-v $((n - 1)) spp: $pt s, MSE $pe"
      [ "$(echo "$pe <= $le" | bc -l)" = 1 ] || break
      n=$((n - 1)) rt=$pt re=$pe
    done
  fi
  c_llvm_t+=("$lt") c_llvm_e+=("$le") c_scal_t+=("$st") c_scal_e+=("$se")
  # rust-v's time at n spp: n times its mean time per spp over all of this round's renders
  # (a render's time is linear in its passes; one render's time alone is noisier).
  rt=$(echo "$n * $tot_t / $tot_n" | bc -l)
  log "  rust-v time to the error: $n spp x $(echo "$tot_t / $tot_n" | bc -l | cut -c1-6) s per spp = $rt s"
  c_r_t+=("$rt") c_r_e+=("$re") c_r_spp+=("$n")
  c_ratio_llvm+=("$(echo "$rt / $lt" | bc -l)") c_ratio_scal+=("$(echo "$rt / $st" | bc -l)")
done

# ---- 2. glass-spheres: error at equal time ----
gref=${GLASS_REF:-}
for c in "$harness/refs/glass-spheres.exr" "$PEERS_DIR/out/ref/glass-spheres.exr"; do
  [ -n "$gref" ] || { [ -f "$c" ] && gref=$c; } || true
done
if [ -z "$gref" ]; then
  gref=$PEERS_DIR/out/ref/glass-spheres.exr
  mkdir -p "$(dirname "$gref")"
  log "no glass-spheres reference: rendering one with llvm_ad_spectral at $glass_ref_spp spp (once)"
  "$py" "$harness/render.py" glass-spheres --variant llvm_ad_spectral --spp "$glass_ref_spp" --seed 1000000 \
    --halves --out "${gref%.exr}" >&2
fi
gscene=$dir/glass-spheres.ron
# The spec's scene: materials-trio.ron's box, light and camera; three smooth constant-IOR spheres.
sed -e 's/^\/\/.*$//' "$here/scenes/materials-trio.ron" \
  | sed -e '/"gold":/d; /"rough_copper":/d; /"rough_glass":/d' \
        -e 's/"green": Lambertian(reflectance: ColorChecker("green")),/&\n        "glass": Dielectric(ior: Constant(1.5)),/' \
        -e 's/material: "gold"/material: "glass"/; s/material: "rough_copper"/material: "glass"/; s/material: "rough_glass"/material: "glass"/' \
  >"$gscene"
g_llvm_t=() g_llvm_e=() g_r_t=() g_r_e=() g_ratio=()
for r in $(seq "$rounds"); do
  seed=$((seed0 + r - 1))
  read -r lt li < <(mitsuba glass-spheres llvm_ad_spectral 64 "$seed")
  need "$lt" "$li"
  le=$(mse "$li" "$gref")
  read -r rt ri < <(rustv "$gscene" 100000 "$seed" --time "$lt")
  need "$rt" "$ri"
  re=$(mse "$ri" "$gref")
  log "glass-spheres round $r: llvm $lt s $le, rust-v $rt s $re ($(sed -n 's/.*(\([0-9]*\) passes.*/\1/p' "$dir/r.err" | tail -1) spp)"
  g_llvm_t+=("$lt") g_llvm_e+=("$le") g_r_t+=("$rt") g_r_e+=("$re") g_ratio+=("$(echo "$re / $le" | bc -l)")
done

fmt() { printf '%.3g' "$1"; }
list() { local o=() v; for v in "$@"; do o+=("$(fmt "$v")"); done; local IFS=','; echo "${o[*]}" | sed 's/,/, /g'; }
echo "**Canonical Cornell box, 256x256, time to Mitsuba llvm's 64-spp linear MSE** ($rounds rounds, seeds $seed0-$((seed0 + rounds - 1)))"
echo
echo "| renderer | spp | render time (s) | linear MSE |"
echo "|---|---|---|---|"
echo "| Mitsuba llvm_ad_spectral | 64 | $(list "${c_llvm_t[@]}") | $(list "${c_llvm_e[@]}") |"
echo "| Mitsuba scalar_spectral | 64 | $(list "${c_scal_t[@]}") | $(list "${c_scal_e[@]}") |"
echo "| rust-v auto | $(list "${c_r_spp[@]}") | $(list "${c_r_t[@]}") | $(list "${c_r_e[@]}") |"
echo
echo "Time to equal error, rust-v / Mitsuba (median of per-round ratios): **$(printf '%.2f' "$(median "${c_ratio_llvm[@]}")")x** llvm_ad_spectral, **$(printf '%.2f' "$(median "${c_ratio_scal[@]}")")x** scalar_spectral."
echo
echo "**glass-spheres, 256x256, error at equal time** (rust-v given Mitsuba llvm's 64-spp render time; reference $(basename "$gref"))"
echo
echo "| renderer | render time (s) | linear MSE |"
echo "|---|---|---|"
echo "| Mitsuba llvm_ad_spectral, 64 spp | $(list "${g_llvm_t[@]}") | $(list "${g_llvm_e[@]}") |"
echo "| rust-v auto, same time | $(list "${g_r_t[@]}") | $(list "${g_r_e[@]}") |"
echo
echo "Error at equal time, rust-v / Mitsuba llvm (median of per-round ratios): **$(printf '%.2f' "$(median "${g_ratio[@]}")")x**."
echo
echo "loadavg after: $(cut -d' ' -f1-3 /proc/loadavg)"
