#!/usr/bin/env bash
# The trixie stage: the project built and tested on Debian 13 "trixie" (libgpiod 2, libcamera 0.4, OpenCV 4.10,
# GCC 14, CMake 3.31), inside a Debian 13 root on this bookworm machine:
#   1. the root (tests/trixie/setup.sh: mmdebstrap from deb.debian.org, cached while its package list holds);
#   2. the build there with the trixie preset (build/trixie, warnings are errors) of what the stage runs;
#   3. the unit, integration and e2e tests there (ctest; the data label and the tests that need Chromium are left
#      to the native stage, see TRIXIE_CTEST_EXCLUDE);
#   4. the kernel tests of the GPIO and camera backends (gpio-sim, vimc, vivid) in the qemu guest, which chroots
#      into the trixie root (tests/kernel/run.sh with KERNEL_GUEST_ROOT): the gpiod 2 and libcamera 0.4 builds
#      against the guest kernel's drivers;
#   5. the .deb built there (cpack), installed with `apt-get install ./avatarbooth_*.deb` (its trixie
#      dependencies), `avatarbooth check` run, and the package purged again so the cached root stays clean.
# Each phase prints its time. The root is a plain chroot with /proc, /sys, /dev and the checkout bound in, in a
# mount namespace of its own (nothing stays mounted after a phase, even when it fails).
# Usage: tests/trixie/run.sh [extra ctest arguments]   (tests/run.sh ci runs it after the arm64 stage; as root)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
rootfs="${TRIXIE_ROOT:-$root/build/trixie-root}"
build="$root/build/trixie"
jobs="$(nproc)"
# The tests the stage leaves to the native stage: those that drive Chromium (its 300 MB of packages would cost
# the root more than the tests are worth here: the browser side does not change with the release), and two of the
# three whole simulated-booth sessions (the retake path and all three reveal styles, 100 s of the stage's 400 s of
# tests): KioskSim.OneScriptedSessionEndToEnd runs the kiosk's whole flow on trixie's libraries, and the other two
# differ from it in the booth's own logic, not in what a release changes.
exclude="${TRIXIE_CTEST_EXCLUDE:-ReportInChromium|^SharePage\.|^KioskSim\.RetakeCameraLost|^KioskSim\.RevealShowsCharacter}"
if [ "$(id -u)" -ne 0 ]; then echo "trixie: run as root (chroot, mounts, mmdebstrap)" >&2; exit 1; fi

shared=""
[ -d "$root/../shared" ] && shared="$(readlink -f "$root/../shared")"

# Runs a shell command inside the root, in the checkout, with the environment a CI shell would have.
in_root() {
  mkdir -p "$rootfs$root"
  unshare --mount --propagation private bash -c '
    set -e
    R=$1; src=$2; cmd=$3; shared=$4
    mount -t proc proc "$R/proc"; mount --rbind /sys "$R/sys"; mount --rbind /dev "$R/dev"
    mount -t tmpfs tmp "$R/tmp"; mount -t tmpfs run "$R/run"
    mkdir -p "$R$src"  # again: a checkout under /tmp (a clone made to try CI) is under the tmpfs just mounted
    mount --bind "$src" "$R$src"
    # The sample data beside the checkout (../shared/data), read-only, for the e2e tests that use it.
    if [ -n "$shared" ]; then mkdir -p "$R$shared"; mount --bind "$shared" "$R$shared"; mount -o remount,bind,ro "$R$shared"; fi
    exec chroot "$R" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root TERM=dumb LANG=C.UTF-8 \
      CI="${CI:-}" EGL_PLATFORM=surfaceless bash -c "cd \"$src\" && $cmd"
  ' in_root "$rootfs" "$root" "$1" "$shared"
}

# CPU seconds (user + system) of every child process waited for so far: a phase's CPU time next to its wall time
# tells what it would take on a quiet machine when other work shares the cores.
cpu_file="$(mktemp)"
trap 'rm -f "$cpu_file"' EXIT
cpu() {  # sets CPU (not in a subshell, where `times` would not see this shell's children)
  times >"$cpu_file"
  CPU=$(awk 'NR == 2 { n = 0; for (i = 1; i <= 2; ++i) { split($i, t, /[ms]/); n += t[1] * 60 + t[2] } printf "%d", n }' "$cpu_file")
}

start=$SECONDS
"$root/tests/trixie/setup.sh" "$rootfs"
cpu; root_done=$SECONDS root_cpu=$CPU
echo "run: trixie root took $((root_done - start)) s (CPU $root_cpu s)"

# The targets the stage runs: the booth and its base head, the test executables, the overlay the .deb carries.
targets="avatarbooth base_head unit_tests integration_tests e2e_tests kernel_tests"
command -v dtc >/dev/null && targets+=" firmware_overlay"
echo "trixie: building (preset trixie, build/trixie: $targets)"
in_root "echo \"trixie: \$(gcc --version | head -1), \$(cmake --version | head -1), libgpiod \$(pkg-config --modversion libgpiod), libcamera \$(pkg-config --modversion libcamera), OpenCV \$(pkg-config --modversion opencv4)\"
  cmake --preset trixie >/dev/null && cmake --build --preset trixie -j $jobs --target $targets"
cpu; build_done=$SECONDS build_cpu=$CPU
echo "run: trixie build took $((build_done - root_done)) s (CPU $((build_cpu - root_cpu)) s)"

# No exit on a failed phase: the later ones still run, and the stage fails if any did.
rc=0
echo "trixie: unit, integration and e2e tests (excluded: $exclude)"
in_root "ctest --preset trixie --timeout 900 --parallel $jobs -L '^(unit|integration|e2e)\$' -E '$exclude' $*" || rc=1
cpu; tests_done=$SECONDS tests_cpu=$CPU
echo "run: trixie tests took $((tests_done - build_done)) s (CPU $((tests_cpu - build_cpu)) s)"

# The guest kernel and its modules are the native stage's (the same bookworm kernel): reuse its cache.
cache="${KERNEL_GUEST_CACHE:-}"
if [ -z "$cache" ]; then
  cache="$build/kernel-guest"
  for c in "$root/build/ci/kernel-guest" "$root/build/release/kernel-guest"; do [ -d "$c" ] && { cache=$c; break; }; done
fi
echo "trixie: kernel tests of the GPIO and camera backends in the guest, chrooted into the trixie root"
KERNEL_GUEST_ROOT="$rootfs" KERNEL_GUEST_BINDS="$root" \
  "$root/tests/kernel/run.sh" "$build/tests/kernel_tests" "$cache" "$build/tests/work/kernel" \
  "${TRIXIE_KERNEL_FILTER:-GpioSim.*:Vimc.*:Vivid.*}" 600 || rc=1
cpu; kernel_done=$SECONDS kernel_cpu=$CPU
echo "run: trixie kernel tests took $((kernel_done - tests_done)) s (CPU $((kernel_cpu - tests_cpu)) s)"

echo "trixie: the .deb, installed in the root with its trixie dependencies, then avatarbooth check"
in_root "set -e
  rm -f build/trixie/avatarbooth_*.deb
  (cd build/trixie && cpack -G DEB >/dev/null)
  deb=\$(ls build/trixie/avatarbooth_*.deb)
  dpkg-deb -f \"\$deb\" Package Version Architecture Depends
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends ./\"\$deb\" | grep -E '^(Setting up|avatarbooth)' || true
  check=0; avatarbooth check || check=\$?
  DEBIAN_FRONTEND=noninteractive apt-get purge -y -q avatarbooth >/dev/null
  echo \"trixie: avatarbooth check exit code \$check\"
  exit \$check" || rc=1
cpu
echo "run: trixie package took $((SECONDS - kernel_done)) s (CPU $((CPU - kernel_cpu)) s)"
echo "trixie: stage took $((SECONDS - start)) s, CPU $CPU s (root $((root_done - start)) s, build $((build_done - root_done)) s," \
     "tests $((tests_done - build_done)) s, kernel tests $((kernel_done - tests_done)) s, package $((SECONDS - kernel_done)) s; exit $rc)"
exit "$rc"
