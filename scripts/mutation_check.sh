#!/usr/bin/env bash
# Mutation check (issue 33, target 6): does the suite catch a 2% gain in each
# integrator and wavelength mode?
#
# Copies the tree (tracked and untracked files, no target/) to a temporary
# directory and patches it once so that every sample and every light-subpath
# splat a render hands to the film is multiplied by 1.02 when the render's
# method is the one named by the environment variable RUST_V_MUTANT
# (whitted, path, hero, random, continuous, auto, bdpt, lighttrace), and by
# exactly 1 otherwise. The funnel is `render_tile` in src/render.rs: every
# estimator's contribution (src/integrator/, src/spectral/) passes through it,
# so the gain is exactly 2% of the method's output, whatever the scene. One
# build serves all eight mutants (the mutant is chosen at run time), then the
# test modules that exercise methods by value run once per mutant, and the
# tests that failed are recorded.
#
# Usage: scripts/mutation_check.sh [OUT_DIR] [TEST FILTERS...]
#   OUT_DIR  where logs and the table go (default: a temporary directory)
#   FILTERS  test-name filters for `cargo test --test main` (default: the
#            modules below). CARGO_TARGET_DIR is honoured (shared builds).
# Also runs the unmutated copy first: a test that fails there is not counted.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$(mktemp -d)}
shift || true
filters=("$@")
if [ ${#filters[@]} -eq 0 ]; then
    filters=(stability:: furnace:: spectral:: auto:: bdpt:: lights::)
fi
mkdir -p "$out"
out=$(cd "$out" && pwd)
copy=$(mktemp -d)/rust-v
trap 'rm -rf "$(dirname "$copy")"' EXIT

# The tree as it is (tracked and untracked, not ignored), without target/.
mkdir -p "$copy"
(cd "$root" && git ls-files -co --exclude-standard -z | xargs -0 cp --parents -t "$copy")
# tests/common.rs reads ../shared relative to the crate: point the copy at the same one.
[ -e "$root/../shared" ] && ln -s "$root/../shared" "$(dirname "$copy")/shared"

python3 - "$copy" <<'PY'
import re, sys
root = sys.argv[1]

def patch(path, old, new):
    p = f"{root}/{path}"
    s = open(p).read()
    assert s.count(old) == 1, (path, old)
    open(p, "w").write(s.replace(old, new))

# Contributions can be scaled (Xyz and Spectrum both implement Mul<f32>).
patch("src/spectral/mod.rs",
      "pub(crate) trait Contribution: Copy + Default + core::ops::AddAssign + Send + Sync + 'static {",
      "pub(crate) trait Contribution: Copy + Default + core::ops::AddAssign + core::ops::Mul<f32, Output = Self> + Send + Sync + 'static {")
gain = '''
    let gain = {
        use crate::settings::{IntegratorKind as I, WavelengthsKind as W};
        let s = &scene.settings;
        let name = match (s.integrator, s.wavelengths) {
            (I::Whitted, _) => "whitted",
            (I::Path, _) => "path",
            (I::Auto, _) => "auto",
            (I::Bdpt, _) => "bdpt",
            (I::LightTrace, _) => "lighttrace",
            (I::Spectral, W::Hero) => "hero",
            (I::Spectral, W::Random) => "random",
            (I::Spectral, W::Continuous) => "continuous",
            (I::Spectral, W::Rgb) => "rgb",
        };
        if std::env::var("RUST_V_MUTANT").as_deref() == Ok(name) { 1.02f32 } else { 1.0f32 }
    };
    let mut out = Vec::with_capacity(tile.len());'''
patch("src/render.rs", "\n    let mut out = Vec::with_capacity(tile.len());", gain)
patch("src/render.rs",
      "out.push(estimator.sample(scene, film_pos, &mut sampler, &mut splats));",
      "out.push(estimator.sample(scene, film_pos, &mut sampler, &mut splats) * gain);")
patch("src/render.rs",
      "(out, by_band(splats, TILE_SIZE))",
      "for s in &mut splats {\n        s.value = s.value * gain;\n    }\n    (out, by_band(splats, TILE_SIZE))")
PY

cd "$copy"
echo "building the mutated copy in $copy (CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$copy/target})" >&2
cargo test --locked --test main --no-run 2>"$out/build.log" || { tail -30 "$out/build.log" >&2; exit 1; }

failed() { { grep -E '^test .* \.\.\. FAILED$' "$1" || true; } | sed -E 's/^test (.*) \.\.\. FAILED$/\1/' | sort; }

for mutant in none whitted path hero random continuous auto bdpt lighttrace; do
    start=$(date +%s)
    RUST_V_MUTANT=$mutant cargo test --locked --test main -- "${filters[@]}" >"$out/$mutant.log" 2>&1 || true
    failed "$out/$mutant.log" >"$out/$mutant.failed"
    echo "$mutant: $(wc -l <"$out/$mutant.failed") failed in $(($(date +%s) - start)) s" >&2
done

{
    echo "| method (2% gain) | tests that caught it |"
    echo "|---|---|"
    for mutant in whitted path hero random continuous auto bdpt lighttrace; do
        caught=$(comm -23 "$out/$mutant.failed" "$out/none.failed" | sed 's/.*/`&`/' | paste -sd, - | sed 's/,/, /g')
        echo "| $mutant | ${caught:-**none**} |"
    done
    if [ -s "$out/none.failed" ]; then
        echo
        echo "Failing without a mutation (not counted): $(paste -sd, "$out/none.failed")"
    fi
} | tee "$out/table.md"
