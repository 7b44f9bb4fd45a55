#!/usr/bin/env bash
# The README's test command: set up (packages, validator, build) and run the whole test suite with ctest.
# Usage: tests/run.sh [PRESET] [extra ctest arguments]   (default preset: release)
# With AVATARBOOTH_ARM64=1 the arm64 stage follows: cross build for the board and the unit tests under qemu-aarch64
# (tests/arm64/run.sh). It is off by default, CI included, until a whole CI run with it is measured under the
# 45-minute budget (the cross build of the whole project alone is about the native build's time again).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"
shift || true
"$root/tests/setup.sh" "$preset"
# Headless EGL through Mesa (llvmpipe) needs no display; keep Mesa from looking for one.
export EGL_PLATFORM=surfaceless
ctest --preset "$preset" --timeout 900 "$@"

if [ "${AVATARBOOTH_ARM64:-0}" = 1 ]; then
  "$root/tests/arm64/run.sh"
fi
