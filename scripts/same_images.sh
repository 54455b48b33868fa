#!/usr/bin/env bash
# Renders every scene in scenes/ with every integrator and wavelength mode, as
# PNG and EXR, with two rust-v binaries, and reports any file that differs.
# For refactors that must not change a single pixel:
#   cargo build --release && cp target/release/rust-v /tmp/old   # on the old commit
#   scripts/same_images.sh /tmp/old target/release/rust-v [SIZE] [SPP]
# NEW_ARGS adds flags to the new binary's renders only, e.g. to check that the
# independent sampler still draws what a binary from before `--sampler` drew:
#   NEW_ARGS="--sampler independent" scripts/same_images.sh /tmp/old target/release/rust-v
set -euo pipefail
old=$1 new=$2 size=${3:-24} spp=${4:-4}
read -r -a new_args <<< "${NEW_ARGS:-}"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
here=$(cd "$(dirname "$0")/.." && pwd)
modes=("--integrator auto" "--integrator path" "--integrator whitted"
       "--integrator spectral --wavelengths hero" "--integrator spectral --wavelengths random"
       "--integrator spectral --wavelengths rgb" "--integrator spectral --wavelengths hero --packet-size 1"
       "--integrator spectral --wavelengths random --packet-size 8" "--integrator auto --packet-size 2"
       "--integrator bdpt" "--integrator lighttrace")
fail=0 n=0
for scene in "$here"/scenes/*.ron; do
  name=$(basename "$scene" .ron)
  for i in "${!modes[@]}"; do
    for ext in png exr; do
      for which in old new; do
        bin=${!which}
        extra=()
        if [[ $which == new ]]; then extra=("${new_args[@]}"); fi
        # shellcheck disable=SC2086
        "$bin" render "$scene" -q --width "$size" --height "$size" --spp "$spp" --seed 7 ${modes[$i]} "${extra[@]}" \
          -o "$dir/$which-$name-$i.$ext" --checkpoint "$dir/$which-$name-$i-$ext.ckpt" 2>"$dir/$which.err" \
          || { echo "FAILED: $which $name ${modes[$i]}"; cat "$dir/$which.err"; fail=1; }
      done
      n=$((n + 1))
      if ! cmp -s "$dir/old-$name-$i.$ext" "$dir/new-$name-$i.$ext"; then
        echo "DIFFERENT: $name ${modes[$i]} .$ext"; fail=1
      fi
    done
  done
done
echo "$n renders compared, $( [ $fail = 0 ] && echo all identical || echo SOME DIFFER )"
exit $fail
