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
rc=0
# -nic none: the tests need no network. panic=-1 and -no-reboot turn a guest crash into qemu exiting.
# debug-threads: the vCPU threads are named ("CPU 0/TCG", ... one per vCPU: multi-threaded TCG) for top -H.
# video=: vkms's screen runs at the booth's small test size (vkms itself prefers 1024x768), as a Pi's cmdline.txt
# chooses a mode; the kernel marks it USERDEF and KmsDisplay takes it. virtio-gpu-pci: a display device the tests
# can take away under an open screen (PCI removal), which vkms cannot be.
timeout -k 10 "$limit" qemu-system-x86_64 $accel -name avatarbooth-kernel,debug-threads=on -m 1024 -smp "$(nproc)" -nographic -no-reboot -nic none -device virtio-gpu-pci \
  -kernel "$kdir/vmlinuz" -initrd "$kdir/initrd.img" \
  -append "console=ttyS0 loglevel=4 panic=-1 edd=off rdinit=/init video=Virtual-1:640x360@60 avatarbooth_kernel_guest=1 wdir=$work kroot=$kdir/kroot gscript=$work/guest.sh${keeptmp:+ keeptmp=$keeptmp}$groot" \
  -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
  -virtfs local,path="$work",mount_tag=work,security_model=none,multidevs=remap < /dev/null || rc=$?
if [ "$rc" -ne 0 ]; then echo "kernel tests: qemu failed or timed out after ${limit} s (exit $rc)"; exit 1; fi
[ -f "$work/rc" ] || { echo "kernel tests: the guest script never finished (no $work/rc)"; exit 1; }
guest_rc=$(cat "$work/rc")
echo "kernel tests: guest exit code $guest_rc, $(( $(date +%s) - start )) s in all"
exit "$guest_rc"
