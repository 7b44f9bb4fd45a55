#!/usr/bin/env bash
# The README's test command: set up (packages, validator, build) and run the whole test suite with ctest.
# Usage: tests/run.sh [PRESET] [extra ctest arguments]   (default preset: release)
# With the ci preset (or AVATARBOOTH_ARM64=1) the arm64 stage follows: cross build for the board and the unit tests
# under qemu-aarch64 (tests/arm64/run.sh). AVATARBOOTH_ARM64=0 leaves it out.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"
shift || true
"$root/tests/setup.sh" "$preset"
# Headless EGL through Mesa (llvmpipe) needs no display; keep Mesa from looking for one.
export EGL_PLATFORM=surfaceless
ctest --preset "$preset" --timeout 900 "$@"

arm64="${AVATARBOOTH_ARM64:-}"
[ -n "$arm64" ] || { [ "$preset" = ci ] && arm64=1 || arm64=0; }
if [ "$arm64" = 1 ]; then
  "$root/tests/arm64/run.sh"
fi
