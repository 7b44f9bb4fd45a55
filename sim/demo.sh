#!/usr/bin/env bash
# The README's main command: set up (packages, build), then run the main job on the embedded default — until the
# kiosk lands, that is `fit` on the bundled synthetic visitor — and say where the avatar and previews are.
# Usage: sim/demo.sh [OUTPUT_FOLDER]   (default: ./out/demo)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/out/demo}"
"$root/tests/setup.sh" release
bin="$root/build/release/app/avatarbooth"
mkdir -p "$out"
"$bin" make-visitor --seed 1 -o "$out/visitor"
"$bin" fit --front "$out/visitor/front.jpg" --side "$out/visitor/side.jpg" -o "$out/session"
