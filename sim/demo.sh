#!/usr/bin/env bash
# The README's main command: set up (packages, then the avatarbooth executable alone: no tests, no benchmarks), run
# the kiosk on the simulated booth for one whole visitor session (headless), and say where the screenshots of every
# screen and the avatar are.
# Usage: sim/demo.sh [OUTPUT_FOLDER]   (default: ./out/demo)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/out/demo}"
"$root/tests/setup.sh" release avatarbooth base_head
bin="$root/build/release/app/avatarbooth"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
# The demo's config: the simulated booth, with the sessions kept in the output folder.
config="$out/booth.toml"
{ cat "$root/sim/demo.toml"; printf '\n[sessions]\ndirectory = "%s"\n' "$out/sessions"; } > "$config"
rm -rf "$out/screens"
"$bin" run --config "$config" --sessions 1 --screenshots "$out/screens"
echo "demo: screenshots of every screen in $out/screens; the visitor's session (avatar.glb, previews) in $out/sessions"
