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
fail=0 n=0 refused=0
for scene in "$here"/scenes/*.ron; do
  name=$(basename "$scene" .ron)
  for i in "${!modes[@]}"; do
    for ext in png exr; do
      declare -A ok=()
      for which in old new; do
        bin=${!which}
        extra=()
        if [[ $which == new ]]; then extra=("${new_args[@]}"); fi
        ok[$which]=1
        # shellcheck disable=SC2086
        "$bin" render "$scene" -q --width "$size" --height "$size" --spp "$spp" --seed 7 ${modes[$i]} "${extra[@]}" \
          -o "$dir/$which-$name-$i.$ext" --checkpoint "$dir/$which-$name-$i-$ext.ckpt" 2>"$dir/$which.err" \
          || ok[$which]=0
      done
      n=$((n + 1))
      if [[ ${ok[old]} == 0 && ${ok[new]} == 0 ]] && cmp -s "$dir/old.err" "$dir/new.err"; then
        # Both binaries refuse the mode with the same error (say, bdpt with a lens system).
        refused=$((refused + 1))
      elif [[ ${ok[old]} == 0 || ${ok[new]} == 0 ]]; then
        echo "FAILED: $name ${modes[$i]} .$ext (old ${ok[old]}, new ${ok[new]}; 0 = refused)"
        cat "$dir/old.err" "$dir/new.err"; fail=1
      elif ! cmp -s "$dir/old-$name-$i.$ext" "$dir/new-$name-$i.$ext"; then
        echo "DIFFERENT: $name ${modes[$i]} .$ext"; fail=1
      fi
      unset ok
    done
  done
done
echo "$n renders compared ($refused refused by both with the same error), $( [ $fail = 0 ] && echo all identical || echo SOME DIFFER )"
exit $fail
