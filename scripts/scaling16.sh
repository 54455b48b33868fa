#!/usr/bin/env bash
# Thread scaling on a many-core host, for docs/performance.md "Thread scaling on 16
# cores": builds named $D/rust-v-VARIANT (VARIANTS, default "256 1024 4096": three
# builds of one commit that differed only in render::MIN_TASKS_PER_BATCH) render each
# scene on 1 thread, on 2, 4 and 8 (the first variant), and 3 times on 16 threads.
# Prints render seconds (the binary's own "N passes in T s", loading excluded), the
# whole process's wall seconds, and an md5 of each image (all must agree per scene:
# the images are bit-identical for any thread count and batch size).
# A portable build for the host:
#   RUSTFLAGS="-C target-cpu=x86-64-v3" cargo build --release
#   mkdir -p target/devrun && cp target/release/rust-v target/devrun/rust-v-1024
#   VARIANTS=1024 scripts/scaling16.sh
# The full dragon needs ../shared/meshes/dragon_vrip.ply.gz copied to
# target/devrun/shared/meshes/ and scenes/full/dragon-full.ron's mesh path pointed there
# (target/devrun/dragon-full.ron).
set -u
VARIANTS=${VARIANTS:-"256 1024 4096"}
cd "$(dirname "$0")/../.."
D=target/devrun
W=$(mktemp -d)
echo "cpu:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-) | $(nproc) cpus"
lscpu | grep -E "^Thread|^Core|^Socket|^NUMA node\(s\)" | tr -s ' ' | paste -sd';'
one() { # variant threads scene args...
  local v=$1 th=$2; shift 2
  local t0 t1 err
  t0=$(date +%s.%N)
  err=$($D/rust-v-$v render "$@" --threads "$th" -o "$W/o.exr" 2>&1 >/dev/null)
  t1=$(date +%s.%N)
  local r; r=$(echo "$err" | grep -o "passes in [0-9.]* s" | awk '{print $3}')
  local l; l=$(echo "$err" | grep -o "loaded in [0-9.]* s" | awk '{print $3}')
  printf '%s v=%s th=%s render=%s load=%s wall=%.3f md5=%s\n' "$NAME" "$v" "$th" "$r" "$l" "$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}')" "$(md5sum < "$W/o.exr" | cut -c1-12)"
}
scene() { # name args...
  NAME=$1; shift
  for v in $VARIANTS; do one $v 1 "$@"; done
  for th in 2 4 8; do one "${VARIANTS%% *}" $th "$@"; done
  for rep in 1 2 3; do for v in $VARIANTS; do one $v 16 "$@"; done; done
}
scene cornell-auto scenes/cornell.ron --width 384 --height 384 --spp 32 --integrator auto
scene spheres-auto scenes/spheres.ron --width 256 --height 256 --spp 32 --integrator auto
scene prism-auto scenes/prism-rainbow.ron --width 384 --height 192 --spp 32 --integrator auto
scene caustic-bdpt scenes/caustic-point.ron --width 256 --height 256 --spp 32 --integrator bdpt
scene cornell-bdpt scenes/cornell.ron --width 256 --height 256 --spp 16 --integrator bdpt
scene dragonfull-auto $D/dragon-full.ron --width 256 --height 256 --spp 16 --integrator auto
echo done
