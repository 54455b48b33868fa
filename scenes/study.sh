#!/usr/bin/env bash
# Reproduces the convergence study of the thesis (chapter 5: Figures 5.2, 5.5, 5.7)
# on the Cornell box, the refracting spheres and the dragon: for each scene a
# reference image (the `auto` integrator: unbiased, and without wavelength noise
# where nothing disperses), then `rust-v converge` with auto, path, hero and random
# sampling and several seeds, writing CSVs and charts. The prism is added for the
# `auto` study (issue 8).
#
# Sized to run in under about 30 minutes on 2 cores (128x128, references at 4096
# spp, checkpoints 1..512 spp, 3 seeds). Override with environment variables:
#   SIZE=256 REF_SPP=20000 MAX_SPP=1024 SEEDS=5 THREADS=2 OUT=study SCENES="cornell spheres" scenes/study.sh
# A scene file that does not exist is skipped with a message.
#
# Output (in $OUT, default ./study): NAME-ref.exr, NAME-converge.csv (every
# record), NAME-summary.csv (min/median/max over seeds), NAME-ratios.csv (hero/random),
# NAME-*.png and NAME-*.svg charts, and study.log with the timings.
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
REPO="$(dirname "$HERE")"
SIZE="${SIZE:-128}"
REF_SPP="${REF_SPP:-4096}"
MAX_SPP="${MAX_SPP:-512}"
SEEDS="${SEEDS:-3}"
METHODS="${METHODS:-auto,path,hero,random}"
OUT="${OUT:-study}"
THREADS_FLAG=()
if [[ -n "${THREADS:-}" ]]; then THREADS_FLAG=(--threads "$THREADS"); fi

schedule="1"
s=2
while ((s <= MAX_SPP)); do
    schedule="$schedule,$s"
    s=$((s * 2))
done

(cd "$REPO" && cargo build --release --quiet)
BIN="$REPO/target/release/rust-v"
mkdir -p "$OUT"
LOG="$OUT/study.log"
echo "study: size ${SIZE}x${SIZE}, reference $REF_SPP spp, schedule $schedule, seeds $SEEDS, methods $METHODS" | tee "$LOG"
start=$(date +%s)

for name in ${SCENES:-cornell spheres dragon prism}; do
    scene="$HERE/$name.ron"
    if [[ ! -f "$scene" ]]; then
        echo "study: $scene does not exist, skipping $name" | tee -a "$LOG"
        continue
    fi
    ref="$OUT/$name-ref.exr"
    t0=$(date +%s)
    if [[ ! -f "$ref" ]]; then
        "$BIN" render "$scene" -o "$ref" --width "$SIZE" --height "$SIZE" --spp "$REF_SPP" \
            --integrator auto --seed 1000000 "${THREADS_FLAG[@]}" --quiet
    fi
    t1=$(date +%s)
    "$BIN" converge "$scene" --reference "$ref" --methods "$METHODS" --seeds "$SEEDS" \
        --spp-schedule "$schedule" --out "$OUT" "${THREADS_FLAG[@]}" --quiet
    t2=$(date +%s)
    echo "study: $name: reference $((t1 - t0)) s, converge $((t2 - t1)) s" | tee -a "$LOG"
done
echo "study: total $(($(date +%s) - start)) s; results in $OUT" | tee -a "$LOG"
