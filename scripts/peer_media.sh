#!/usr/bin/env bash
# rust-v against Mitsuba 3 on a chromatic homogeneous medium in the Cornell box (issue 30):
# runs scripts/peer_media.py (which see) with the Mitsuba harness's venv python.
#
#   scripts/peer_media.sh [--bin BINARY] [--seeds 8] [--mitsuba-spp 1024] [--rustv-spp 2048] [--speed 5] ...
#
# Needs the harness ../shared/peers/mitsuba and its venv (bash ../shared/peers/mitsuba/setup.sh)
# and a release build (cargo build --release).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
py=${MITSUBA_VENV:-${PEERS_DIR:-$HOME/.cache/peers}/mitsuba-venv}/bin/python
[ -x "$py" ] || { echo "no Mitsuba venv at $py: run bash ../shared/peers/mitsuba/setup.sh" >&2; exit 1; }
exec "$py" "$here/scripts/peer_media.py" "$@"
