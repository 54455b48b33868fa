#!/usr/bin/env bash
# Downloads a few small, all-text scenes of the public pbrt-v4-scenes collection
# (https://github.com/mmp/pbrt-v4-scenes; see its README for each scene's licence)
# into ../shared/pbrt-v4-scenes/ beside the repository, outside it: tests/pbrt.rs
# loads and renders them when they are there, and skips them otherwise.
#   scripts/fetch-pbrt-scenes.sh [DEST]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dest=${1:-$here/../shared/pbrt-v4-scenes}
base=${PBRT_SCENES_URL:-https://raw.githubusercontent.com/mmp/pbrt-v4-scenes/master}
files=(
  killeroos/killeroo-simple.pbrt
  killeroos/geometry/killeroo.pbrt
)
for f in "${files[@]}"; do
  mkdir -p "$dest/$(dirname "$f")"
  curl -fsSL "$base/$f" -o "$dest/$f"
  echo "fetched $f"
done
