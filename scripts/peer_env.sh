#!/usr/bin/env bash
# rust-v against Mitsuba 3 on scenes/environment.ron, time to equal error (issue 35): runs
# scripts/peer_env.py (which see) with the Mitsuba harness's venv python.
#
#   scripts/peer_env.sh [--bin BINARY] [--rounds 3] [--ref-spp 4096] [--out DIR] [--integrator auto]
#
# Needs the harness ../shared/peers/mitsuba and its venv (bash ../shared/peers/mitsuba/setup.sh),
# a release build (cargo build --release) and scenes/textures/outdoor.exr
# (cargo run --release --example make_textures).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
py=${MITSUBA_VENV:-${PEERS_DIR:-$HOME/.cache/peers}/mitsuba-venv}/bin/python
[ -x "$py" ] || { echo "no Mitsuba venv at $py: run bash ../shared/peers/mitsuba/setup.sh" >&2; exit 1; }
exec "$py" "$here/scripts/peer_env.py" "$@"
