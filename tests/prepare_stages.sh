#!/usr/bin/env bash
# Makes ready, while the native build runs, what the later test stages download and unpack: the kernel guest
# (kernel, headers and source from apt, its three out-of-tree modules: tests/kernel/setup.sh), the arm64 sysroot
# (tests/arm64/setup.sh) and the Debian 13 root (tests/trixie/setup.sh). Started by tests/run.sh in the
# background once the packages are installed; it waits for this before the tests start, so that nothing downloads
# beside a test that times the booth.
# They wait on the mirror, and unpack and configure packages: what they wait no longer adds to the run, what they
# compute slows the build beside them (README, "Building for the board", has both figures). Each set-up keeps what
# it made under a key and its stage runs it again: a failure here only prints, and the stage makes the same
# attempt and fails with the full message if it fails again.
# Usage: tests/prepare_stages.sh KERNEL_CACHE_DIR ARM64(0|1) TRIXIE(0|1) LOG_DIR
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
kernel_cache="${1:?usage: prepare_stages.sh KERNEL_CACHE_DIR ARM64 TRIXIE LOG_DIR}"
arm64="${2:?arm64 0|1}"
trixie="${3:?trixie 0|1}"
logs="${4:?log dir}"
mkdir -p "$logs"

# Runs one set-up with its output in LOG_DIR/NAME.log and prints one line: its time, or its failure and log's end.
prepare() {
  local name=$1; shift
  local start=$SECONDS rc=0
  "$@" >"$logs/$name.log" 2>&1 || rc=$?
  if [ "$rc" -eq 0 ]; then
    echo "prepare: $name ready in $((SECONDS - start)) s"
  else
    echo "prepare: $name failed (exit $rc) after $((SECONDS - start)) s; its stage will try again. Its log ends:"
    tail -n 5 "$logs/$name.log" | sed 's/^/prepare:   /'
  fi
}

# The three at once: together they end inside the build.
prepare kernel-guest "$root/tests/kernel/setup.sh" "$kernel_cache" &
[ "$arm64" = 1 ] && prepare arm64-sysroot "$root/tests/arm64/setup.sh" &
[ "$trixie" = 1 ] && prepare trixie-root "$root/tests/trixie/setup.sh" &
wait
exit 0
