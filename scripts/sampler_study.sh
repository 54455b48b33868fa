#!/usr/bin/env bash
# The sampler study of issue 18: `rust-v converge` with the `sobol` and the
# `independent` sampler on the same scenes, methods and seeds, interleaved (the
# machine may be shared: each scene runs sobol, independent, sobol, independent
# ... ROUNDS times, and /proc/loadavg is logged before every run), then
# scripts/sampler_study.py fits the error slopes and the time to equal error.
#
#   SIZE=64 REF_SPP=2048 MAX_SPP=256 SEEDS=2 ROUNDS=1 METHODS=auto \
#     SCENES="cornell spheres prism" OUT=study-sampler scripts/sampler_study.sh
#
# Output in $OUT: NAME-ref.exr (auto, independent, seed 1000000), one
# converge directory per sampler and round (sobol-R/, independent-R/ with
# NAME-converge.csv), study.log (timings and load), and the table on stdout.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
REPO="$(dirname "$HERE")"
SIZE="${SIZE:-64}" REF_SPP="${REF_SPP:-2048}" MAX_SPP="${MAX_SPP:-256}" SEEDS="${SEEDS:-2}"
ROUNDS="${ROUNDS:-1}" METHODS="${METHODS:-auto}" OUT="${OUT:-study-sampler}"
THREADS_FLAG=()
if [[ -n "${THREADS:-}" ]]; then THREADS_FLAG=(--threads "$THREADS"); fi
schedule="1"
s=2
while ((s <= MAX_SPP)); do schedule="$schedule,$s"; s=$((s * 2)); done
(cd "$REPO" && cargo build --release --locked --quiet)
BIN="$REPO/target/release/rust-v"
mkdir -p "$OUT"
LOG="$OUT/study.log"
echo "sampler study: ${SIZE}x${SIZE}, reference $REF_SPP spp, schedule $schedule, seeds $SEEDS, rounds $ROUNDS, methods $METHODS; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)" | tee "$LOG"
for name in ${SCENES:-cornell spheres prism}; do
    scene="$REPO/scenes/$name.ron"
    ref="$OUT/$name-ref.exr"
    if [[ ! -f "$ref" ]]; then
        t0=$(date +%s.%N)
        "$BIN" render "$scene" -o "$ref" --width "$SIZE" --height "$SIZE" --spp "$REF_SPP" \
            --integrator auto --sampler independent --seed 1000000 "${THREADS_FLAG[@]}" --quiet
        echo "$name: reference $(echo "$(date +%s.%N) - $t0" | bc) s" | tee -a "$LOG"
    fi
    for ((r = 1; r <= ROUNDS; r++)); do
        for sampler in sobol independent; do
            echo "$name round $r $sampler: load $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$LOG"
            mkdir -p "$OUT/$sampler-$r"
            "$BIN" converge "$scene" --reference "$ref" --methods "$METHODS" --seeds "$SEEDS" \
                --spp-schedule "$schedule" --out "$OUT/$sampler-$r" --width "$SIZE" --height "$SIZE" \
                --sampler "$sampler" "${THREADS_FLAG[@]}" --quiet
        done
    done
done
python3 "$HERE/sampler_study.py" "$OUT" | tee -a "$LOG"
