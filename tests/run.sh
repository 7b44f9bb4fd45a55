#!/usr/bin/env bash
# The README's test command: set up (packages, validator, build) and run the whole test suite with ctest, one test
# per core (tests that time the booth or take the whole machine are RUN_SERIAL: tests/CMakeLists.txt).
# Usage: tests/run.sh [PRESET] [extra ctest arguments]   (default preset: release)
#
# With the ci preset (.ci/run) the arm64 stage follows: cross build for the board and the unit tests under
# qemu-aarch64 (tests/arm64/run.sh). AVATARBOOTH_ARM64=0 leaves it out, AVATARBOOTH_ARM64=1 adds it to other presets.
# Then the trixie stage: the build and the tests in a Debian 13 root, the kernel tests of the gpiod 2 and
# libcamera 0.4 builds in the guest, the .deb installed there (tests/trixie/run.sh). AVATARBOOTH_TRIXIE=0/1 likewise.
# CI's budget is 45 minutes for all of it on a fresh 2-core machine; the README ("Building for the board") has the
# measured figures of each phase. Each phase prints its time ("run: ... took N s"). The later stages' downloads run
# beside the native build (tests/prepare_stages.sh).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"
shift || true
arm64_default=0
[ "$preset" = ci ] && arm64_default=1
arm64="${AVATARBOOTH_ARM64:-$arm64_default}"
trixie="${AVATARBOOTH_TRIXIE:-$arm64_default}"

start=$SECONDS
# The packages first; then the later stages' downloads (tests/prepare_stages.sh) run beside the native build.
"$root/tests/setup.sh" --install-only
prepare_log="$root/build/$preset/prepare"
# set -m: a background job in a process group of its own, so that one kill stops it and all it started.
set -m
"$root/tests/prepare_stages.sh" "$root/build/$preset/kernel-guest" "$arm64" "$trixie" "$prepare_log" &
prepare_pid=$!
set +m
trap 'kill -- -$prepare_pid 2>/dev/null || true' EXIT  # a failed build leaves no download behind
"$root/tests/setup.sh" "$preset"
build_done=$SECONDS
wait "$prepare_pid" || true
trap - EXIT
setup_done=$SECONDS
echo "run: set-up and native build took $((build_done - start)) s, then $((setup_done - build_done)) s waiting for the later stages' set-ups (logs in $prepare_log)"

# Headless EGL through Mesa (llvmpipe) needs no display; keep Mesa from looking for one.
export EGL_PLATFORM=surfaceless
# No `exit` on failure before the arm64 and trixie stages: CI reports all, and fails if any failed.
rc=0
ctest --preset "$preset" --timeout 900 --parallel "$(nproc)" "$@" || rc=$?
tests_done=$SECONDS
echo "run: native tests took $((tests_done - setup_done)) s"

if [ "$arm64" = 1 ]; then
  "$root/tests/arm64/run.sh" || rc=$?
  echo "run: arm64 stage took $((SECONDS - tests_done)) s"
fi
if [ "$trixie" = 1 ]; then
  trixie_start=$SECONDS
  "$root/tests/trixie/run.sh" || rc=$?
  echo "run: trixie stage took $((SECONDS - trixie_start)) s"
fi
echo "run: $((SECONDS - start)) s in all (exit $rc)"
exit "$rc"
