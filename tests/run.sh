#!/usr/bin/env bash
# The README's test command: set up (packages, validator, build) and run the whole test suite with ctest.
# Usage: tests/run.sh [PRESET] [extra ctest arguments]   (default preset: release)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"
shift || true
"$root/tests/setup.sh" "$preset"
# Headless EGL through Mesa (llvmpipe) needs no display; keep Mesa from looking for one.
export EGL_PLATFORM=surfaceless
ctest --preset "$preset" --timeout 900 "$@"
