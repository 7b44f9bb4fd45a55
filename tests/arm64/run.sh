#!/usr/bin/env bash
# The arm64 stage: make (or reuse) the arm64 sysroot, cross-build what the board runs and what is tested here with
# the arm64 preset (warnings are errors): the avatarbooth executable and the unit tests, which run
# under qemu-aarch64 through ctest's cross-compiling emulator. The other test executables need EGL, files or a
# kernel guest and never run here; the native stage compiles them with the same warnings, so the cross build leaves
# them out (it halves the stage on a 2-core machine).
# Usage: tests/arm64/run.sh [extra ctest arguments]   (tests/run.sh ci runs it after the native tests)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
start=$SECONDS
"$root/tests/arm64/setup.sh"
sysroot_done=$SECONDS
echo "arm64: cross-building (preset arm64, build/arm64)"
cmake --preset arm64 >/dev/null
cmake --build --preset arm64 -j "$(nproc)" --target avatarbooth unit_tests
build_done=$SECONDS
readelf -h build/arm64/app/avatarbooth | grep -q 'Machine:.*AArch64' ||
  { echo "arm64: build/arm64/app/avatarbooth is not an arm64 executable" >&2; exit 1; }
echo "arm64: unit tests under qemu-aarch64"
ctest --preset arm64 "$@"
echo "arm64: stage took $((SECONDS - start)) s (sysroot $((sysroot_done - start)) s, build $((build_done - sysroot_done)) s," \
     "emulated unit tests $((SECONDS - build_done)) s)"
