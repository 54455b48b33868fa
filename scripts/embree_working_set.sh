#!/usr/bin/env bash
# Ray casting against Embree as the working set grows (issue 18, docs/performance.md
# round 4): the first N incoherent rays of the Embree harness, repeated to 1,000,000 rays,
# traced by Embree's harness and by rust-v's `embree_rays` example, round after round.
# With N = 1000 the touched nodes and triangles stay in the L2 cache, so the two sides
# compare as computation; with larger N they compare as memory traffic too. Prints a
# markdown table of median Mrays/s (wall time of a pass; median of ROUNDS rounds of 5
# passes each).
#
#   EMBREE_VENV=... EMBREE_DATA=... scripts/embree_working_set.sh [EMBREE_RAYS_BINARY]
#   SIZES="1000 10000 100000" ROUNDS=3 scripts/embree_working_set.sh
#
# Needs the harness ../shared/peers/embree with its venv and its incoherent ray file for
# dragon_vrip (bash ../shared/peers/embree/setup.sh; python make_rays.py), and the mesh in
# ../shared/meshes. The subsets are written under $WORK (default a temporary directory,
# removed at the end): 24 MB per size.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$here/target/release/examples/embree_rays}")
harness=$(realpath "${HARNESS:-$here/../shared/peers/embree}")
export PEERS_DIR=${PEERS_DIR:-$HOME/.cache/peers}
py=${EMBREE_VENV:-$PEERS_DIR/embree-venv}/bin/python
data=${EMBREE_DATA:-$PEERS_DIR/embree-data}
sizes=${SIZES:-1000 10000 100000}
rounds=${ROUNDS:-3}
[ -x "$bin" ] || { echo "no $bin: cargo build --release --example embree_rays" >&2; exit 1; }
[ -x "$py" ] || { echo "no $py: bash $harness/setup.sh" >&2; exit 1; }
src=$data/rays/dragon_vrip.incoherent.rays
[ -f "$src" ] || { echo "no $src: run the harness's make_rays.py" >&2; exit 1; }
work=${WORK:-$(mktemp -d)}
[ -n "${WORK:-}" ] || trap 'rm -rf "$work"' EXIT

median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

echo "| first N rays, repeated to 1M | Embree Mrays/s | rust-v Mrays/s | rust-v / Embree |"
echo "|---|---|---|---|"
for n in $sizes; do
  dir=$work/n$n
  mkdir -p "$dir/rays" "$dir/hits" "$dir/results"
  # The subset and a sidecar whose ray hash matches it (the harness checks it).
  "$py" - "$src" "$dir/rays/dragon_vrip.incoherent.rays" "$n" <<'EOF'
import hashlib, json, sys
import numpy as np
src, dst, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
rays = np.fromfile(src, dtype="<f4").reshape(-1, 6)[:n]
out = np.tile(rays, (1_000_000 // n, 1))
out.tofile(dst)
side = json.load(open(src + ".json"))
side["rays_sha256"] = hashlib.sha256(out.tobytes()).hexdigest()
side["n"] = len(out)
side["subset"] = f"first {n} rays of {src}, repeated"
json.dump(side, open(dst + ".json", "w"), indent=2)
EOF
  e=(); r=()
  for ((k = 0; k < rounds; k++)); do
    e+=("$(cd "$harness" && "$py" embree_bench.py --mesh dragon_vrip --rounds 1 --data "$dir" \
      --kinds incoherent --no-hits --build-repeats 1 | grep -E '^incoherent' | grep -oE '[0-9.]+ Mrays/s median' | cut -d' ' -f1)")
    r+=("$(EMBREE_DATA=$dir "$bin" --kinds incoherent --passes 5 --no-hits | grep -oE '[0-9.]+ Mrays/s median' | cut -d' ' -f1)")
    echo "N=$n round $((k + 1)): Embree ${e[-1]}, rust-v ${r[-1]}" >&2
  done
  e_med=$(printf '%s\n' "${e[@]}" | median)
  r_med=$(printf '%s\n' "${r[@]}" | median)
  echo "| $n | $e_med | $r_med | $(awk -v a="$r_med" -v b="$e_med" 'BEGIN {printf "%.2f", a / b}') |"
done
