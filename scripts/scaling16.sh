#!/usr/bin/env bash
# Thread scaling on a many-core host (docs/performance.md, "Thread scaling on 16 cores"):
# for each integrator, a render of 5-9 s on one thread, timed
#   - alone on 1 thread (twice, before and after),
#   - as 16 one-thread copies at once: the host's own ceiling for this work (turbo,
#     shared caches and memory, neighbours on a virtual machine all show here),
#   - on 16 threads (3 times);
# then the full dragon's load (1 and 16 threads) and whole process, and the time to
# inflate its .ply.gz alone (python's zlib, gzip). Render rates are the binary's own
# "N Msamples/s" (loading excluded); "wall" is the whole process; every image's md5 must
# agree per scene (bit-identical for any thread count).
#
# A portable build, carried to the host in an ignored folder:
#   RUSTFLAGS="-C target-cpu=x86-64-v3" cargo build --release
#   mkdir -p target/devrun && cp target/release/rust-v target/devrun/rust-v && strip target/devrun/rust-v
# The full dragon needs ../shared/meshes/dragon_vrip.ply.gz copied to
# target/devrun/shared/meshes/ and a copy of scenes/full/dragon-full.ron as
# target/devrun/dragon-full.ron with its mesh path "../../target/devrun/shared/meshes/dragon_vrip.ply.gz".
# About 4 minutes on a 16-core Xeon.
set -u
cd "$(dirname "$0")/.."
D=target/devrun
W=$(mktemp -d)
echo "cpu:$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-) | $(nproc) cpus"
lscpu | grep -E "^Thread|^Core|^Socket|^NUMA node\(s\)" | tr -s ' ' | paste -sd';'
one() { # threads name args...
  local th=$1 name=$2; shift 2
  local t0 t1 f=$W/e
  t0=$(date +%s.%N)
  $D/rust-v render "$@" --threads "$th" -o "$W/o.exr" >/dev/null 2>"$f"
  t1=$(date +%s.%N)
  printf '%s th=%s render=%s load=%s wall=%.3f md5=%s\n' "$name" "$th" \
    "$(grep -o "in [0-9.]* s, [0-9.]* Msamples/s" "$f" | awk '{print $2" s/"$4" Ms/s"}')" \
    "$(grep -o "loaded in [0-9.]* s" "$f" | awk '{print $3}')" \
    "$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}')" "$(md5sum < "$W/o.exr" | cut -c1-12)"
}
# The copies' rates summed overstate the ceiling (the last ones run on an emptier chip);
# their total work over "wall" (until the last one finished) understates it slightly.
ceiling() { # name args...
  local name=$1; shift
  local t0; t0=$(date +%s.%N)
  for i in $(seq 16); do $D/rust-v render "$@" --threads 1 -o "$W/c$i.exr" >/dev/null 2>"$W/c$i.err" & done
  wait
  printf '%s ceiling16 Ms/s=%s wall=%.3f\n' "$name" "$(cat "$W"/c*.err | grep -o "[0-9.]* Msamples/s" | awk '{print $1}' | sort -n | paste -sd' ')" \
    "$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{print b-a}')"
  rm -f "$W"/c*
}
scene() { # name args...
  local name=$1; shift
  one 1 "$name" "$@"; ceiling "$name" "$@"
  for rep in 1 2 3; do one 16 "$name" "$@"; done
  one 1 "$name" "$@"
}
G=$D/shared/meshes/dragon_vrip.ply.gz
if [ -f "$G" ]; then
  for rep in 1 2 3; do
    python3 -c "import zlib,time; d=open('$G','rb').read(); t=time.time(); zlib.decompress(d,47); print('inflate zlib %.4f s' % (time.time()-t))"
    t0=$(date +%s.%N); gzip -dc < "$G" > /dev/null; echo "inflate gzip $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN{print b-a}') s"
  done
  for rep in 1 2 3 4 5; do one 16 dragon-load $D/dragon-full.ron --width 8 --height 8 --spp 1; done
  for rep in 1 2; do one 1 dragon-load $D/dragon-full.ron --width 8 --height 8 --spp 1; done
  one 1 dragon-whole $D/dragon-full.ron --width 256 --height 256 --spp 16
  for rep in 1 2 3; do one 16 dragon-whole $D/dragon-full.ron --width 256 --height 256 --spp 16; done
  one 1 dragon-whole $D/dragon-full.ron --width 256 --height 256 --spp 16
fi
scene cornell-auto scenes/cornell.ron --width 384 --height 384 --spp 48 --integrator auto
scene cornell-whitted scenes/cornell.ron --width 384 --height 384 --spp 112 --integrator whitted
scene caustic-lighttrace scenes/caustic-point.ron --width 256 --height 256 --spp 256 --integrator lighttrace
scene prism-auto scenes/prism-rainbow.ron --width 384 --height 192 --spp 48 --integrator auto
scene caustic-bdpt scenes/caustic-point.ron --width 256 --height 256 --spp 88 --integrator bdpt
scene cornell-bdpt scenes/cornell.ron --width 256 --height 256 --spp 32 --integrator bdpt
scene prism-spectral scenes/prism-rainbow.ron --width 384 --height 192 --spp 144 --integrator spectral
scene spheres-path scenes/spheres.ron --width 256 --height 256 --spp 72 --integrator path
scene env-caustics scenes/environment.ron --width 256 --height 256 --spp 80 --integrator caustics
echo done
