#!/usr/bin/env bash
# Thread scaling of every integrator: wall time of `rust-v render --threads 1`
# against `--threads 2`, interleaved (one 1-thread and one 2-thread render per
# round, so both see the same machine load), ROUNDS rounds; prints a markdown
# table of the medians and the median of the per-round ratios t1 / t2.
#
#   scripts/scaling.sh [BINARY]            # default target/release/rust-v
#   SCENES="cornell spheres" SIZE=256 SPP=32 ROUNDS=3 THREADS=2 scripts/scaling.sh
#
# SPP is per integrator where one default would take too long or too short:
# SPP_bdpt, SPP_lighttrace, SPP_whitted override SPP for that integrator. The
# images are not kept. The load average before and after is printed: a ratio
# measured while other jobs run is a lower bound on the scaling (the second
# thread competes with them), so rerun it on an idle machine before quoting it.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$here/target/release/rust-v}
scenes=${SCENES:-"cornell spheres"}
size=${SIZE:-256}
spp=${SPP:-32}
rounds=${ROUNDS:-3}
threads=${THREADS:-2}
integrators=${INTEGRATORS:-"auto path spectral whitted bdpt lighttrace"}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

# Wall seconds of one quiet render (GNU time's %e, or bash's clock as a fallback).
wall() {
  local t0 t1
  t0=$(date +%s.%N)
  "$bin" render "$@" -q -o "$dir/out.exr" >/dev/null 2>"$dir/err" || { cat "$dir/err" >&2; exit 1; }
  t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc -l
}

median() { printf '%s\n' "$@" | sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }

echo "rust-v thread scaling: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) CPUs"
echo "binary $bin, ${size}x${size}, $rounds interleaved rounds; loadavg before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| scene | integrator | spp | 1 thread (s) | $threads threads (s) | ratio (median of rounds) |"
echo "|---|---|---|---|---|---|"
for scene in $scenes; do
  for integ in $integrators; do
    var=SPP_$integ
    n=${!var:-$spp}
    args=("$here/scenes/$scene.ron" --width "$size" --height "$size" --spp "$n" --integrator "$integ")
    one=() two=() ratio=()
    for _ in $(seq "$rounds"); do
      a=$(wall "${args[@]}" --threads 1)
      b=$(wall "${args[@]}" --threads "$threads")
      one+=("$a") two+=("$b") ratio+=("$(echo "$a / $b" | bc -l)")
    done
    printf '| %s | %s | %s | %.2f | %.2f | %.3f |\n' "$scene" "$integ" "$n" \
      "$(median "${one[@]}")" "$(median "${two[@]}")" "$(median "${ratio[@]}")"
  done
done
echo
echo "loadavg after: $(cut -d' ' -f1-3 /proc/loadavg)"
