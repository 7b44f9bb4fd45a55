#!/usr/bin/env bash
# Runs the `kernel` tests: prepares (or reuses) the guest (setup.sh), boots Debian's stock kernel under
# qemu-system-x86_64 (TCG: no KVM, no host modules) with the host's root shared read-only over 9p, and runs the
# kernel_tests GoogleTest executable inside it against vivid, gpio-sim and vimc. Exit code: the tests'.
# Usage: tests/kernel/run.sh KERNEL_TESTS_BINARY CACHE_DIR WORK_DIR [GTEST_FILTER] [TIMEOUT_S]
# KERNEL_GUEST_ROOT=DIR: the guest chroots into DIR (a root of another Debian release that the binary was built in,
# e.g. tests/trixie/) instead of the host's /, with the host folders KERNEL_GUEST_BINDS names (comma-separated:
# the checkout, which holds the binary, this cache and the work folder) bound in at their own paths.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
binary=$(readlink -f "${1:?usage: run.sh KERNEL_TESTS_BINARY CACHE_DIR WORK_DIR [GTEST_FILTER] [TIMEOUT_S]}")
cache=${2:?cache dir}
work=$(readlink -m "${3:?work dir}")
filter=${4:-*}
limit=${5:-840}  # under ctest's 900 s for kernel_guest
# A suite that takes longer than this is stopped (where it waits is printed) and run once more (twice stopped:
# it fails); the Daemon suite gets twice this. Vkms takes about 25 s, Daemon 50-130 s under TCG.
suite_limit=${KERNEL_SUITE_TIMEOUT:-150}

start=$(date +%s)
kdir=$("$here/setup.sh" "$cache")
echo "kernel tests: guest kernel $(basename "$kdir") ready after $(( $(date +%s) - start )) s"

# The work folder is shared read-write; the guest's /tmp is a tmpfs, so everything it writes goes here.
rm -rf "$work"; mkdir -p "$work"
cat > "$work/guest.sh" <<GUEST
# Runs inside the guest (root, chrooted into the host's root; \$W = this folder, \$KMOD_ROOT = guest modules).
echo "[guest] running $binary"
/bin/bash "$here/guest_suites.sh" "$binary" '$filter' "$suite_limit"
GUEST
# The guest mounts a tmpfs of its own on /tmp (the host root is read-only to it), which would hide a checkout
# under the host's /tmp (a clone made to try the set-up), and the work folder's mount point with it. Such
# folders are named to the guest, which binds them back from the host's /tmp over its tmpfs.
keeptmp=""
for p in "$binary" "$kdir" "$here" "$work"; do
  case "$p" in /tmp/?*) top=/tmp/$(echo "${p#/tmp/}" | cut -d/ -f1)
    case ",$keeptmp," in *",$top,"*) ;; *) keeptmp=${keeptmp:+$keeptmp,}$top;; esac;; esac
done
groot=""
if [ -n "${KERNEL_GUEST_ROOT:-}" ]; then
  groot=" groot=$(readlink -f "$KERNEL_GUEST_ROOT") gbind=${KERNEL_GUEST_BINDS:-}"
  # The guest cannot make mount points in the read-only host root: they are made here.
  for d in $(echo "${KERNEL_GUEST_BINDS:-}" | tr , ' '); do mkdir -p "$KERNEL_GUEST_ROOT$d"; done
fi
accel="-accel tcg,thread=multi -cpu max"
# A guest that says nothing on its console for this long has stalled as a whole (a suite stuck alone is stopped by
# guest_suites.sh, which says so, after at most twice suite_limit): qemu is stopped and the guest booted once more
# within what is left of the limit. Seen once (2026-12-05): every Vimc test passed, then no word for 12 minutes,
# guest_suites.sh's own watchdog silent too, until the limit.
silence=${KERNEL_GUEST_SILENCE_S:-$(( 2 * suite_limit + 30 ))}
rc=0
# Boots the guest with `budget` seconds; qemu's exit code (124: out of time), 125 when the guest fell silent.
# -nic none: the tests need no network. panic=-1 and -no-reboot turn a guest crash into qemu exiting.
# debug-threads: the vCPU threads are named ("CPU 0/TCG", ... one per vCPU: multi-threaded TCG) for top -H.
# video=: vkms's screen runs at the booth's small test size (vkms itself prefers 1024x768), as a Pi's cmdline.txt
# chooses a mode; the kernel marks it USERDEF and KmsDisplay takes it. virtio-gpu-pci: a display device the tests
# can take away under an open screen (PCI removal), which vkms cannot be.
boot_guest() {
  local budget=$1 log="$work/console.log" qpid size last lastsize=-1
  : > "$log"
  timeout -k 10 "$budget" qemu-system-x86_64 $accel -name avatarbooth-kernel,debug-threads=on -m 1024 -smp "$(nproc)" -nographic -no-reboot -nic none -device virtio-gpu-pci \
  -kernel "$kdir/vmlinuz" -initrd "$kdir/initrd.img" \
  -append "console=ttyS0 loglevel=4 panic=-1 edd=off rdinit=/init video=Virtual-1:640x360@60 avatarbooth_kernel_guest=1 wdir=$work kroot=$kdir/kroot gscript=$work/guest.sh${keeptmp:+ keeptmp=$keeptmp}$groot" \
  -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
  -virtfs local,path="$work",mount_tag=work,security_model=none,multidevs=remap < /dev/null > "$log" 2>&1 &
  qpid=$!
  tail -f --pid="$qpid" "$log" &  # the console, as it comes
  last=$(date +%s)
  while kill -0 "$qpid" 2>/dev/null; do
    sleep 5
    size=$(stat -c %s "$log")
    if [ "$size" != "$lastsize" ]; then lastsize=$size; last=$(date +%s); fi
    if [ $(( $(date +%s) - last )) -ge "$silence" ]; then
      echo "kernel tests: the guest said nothing for $silence s: stopped"
      kill "$qpid" 2>/dev/null; wait "$qpid" 2>/dev/null; sleep 1
      return 125
    fi
  done
  wait "$qpid"
}
boot_guest "$limit" || rc=$?
if [ "$rc" -eq 125 ]; then
  left=$(( limit - ($(date +%s) - start) ))
  find "$work" -mindepth 1 ! -name guest.sh -delete  # what the stalled guest wrote
  echo "kernel tests: booting the guest once more, with the $left s left"
  rc=0
  [ "$left" -gt 60 ] && { boot_guest "$left" || rc=$?; } || rc=124
fi
if [ "$rc" -ne 0 ]; then echo "kernel tests: qemu failed, timed out or fell silent within ${limit} s (exit $rc)"; exit 1; fi
[ -f "$work/rc" ] || { echo "kernel tests: the guest script never finished (no $work/rc)"; exit 1; }
guest_rc=$(cat "$work/rc")
echo "kernel tests: guest exit code $guest_rc, $(( $(date +%s) - start )) s in all"
exit "$guest_rc"
