#!/usr/bin/env bash
# Regenerates what is rendered from the config schema (app/config/config_schema.cpp): app/assets/booth.toml from
# `avatarbooth config --print-default`, and the README's config reference (between the config-reference markers)
# from `avatarbooth config --reference`. The unit tests Config.ShippedFileIsThePrintedDefault and
# Config.ReadmeReferenceIsGenerated fail until this has been run after a change to the schema.
# Usage: tests/update_config_reference.sh [BUILD_DIR]   (default: build/release; the avatarbooth target built)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${1:-$root/build/release}/app/avatarbooth"
[ -x "$bin" ] || { echo "update_config_reference: $bin not built (cmake --build BUILD_DIR --target avatarbooth)" >&2; exit 1; }

"$bin" config --print-default > "$root/app/assets/booth.toml.new"
mv "$root/app/assets/booth.toml.new" "$root/app/assets/booth.toml"

reference="$(mktemp)"
trap 'rm -f "$reference" "$root/README.md.new"' EXIT
"$bin" config --reference > "$reference"
begin='<!-- config-reference:begin -->'
end='<!-- config-reference:end -->'
grep -qxF "$begin" "$root/README.md" && grep -qxF "$end" "$root/README.md" ||
    { echo "update_config_reference: README.md lacks the lines $begin and $end" >&2; exit 1; }
# Keep everything up to and including the begin marker and from the end marker on; the reference goes between.
awk -v begin="$begin" -v end="$end" -v file="$reference" '
    $0 == begin { print; while ((getline line < file) > 0) print line; skipping = 1; next }
    $0 == end { skipping = 0 }
    !skipping { print }' "$root/README.md" > "$root/README.md.new"
mv "$root/README.md.new" "$root/README.md"
echo "update_config_reference: wrote app/assets/booth.toml and the README's config reference"
