#!/usr/bin/env bash
# arm64 (the board's architecture) set-up: installs the cross toolchain, qemu-user and mmdebstrap when missing, and
# makes the arm64 sysroot the cross build (cmake/toolchains/aarch64-linux-gnu.cmake) compiles, links and runs against.
# Usage: tests/arm64/setup.sh [SYSROOT]   (default: build/arm64-sysroot; also ARM64_SYSROOT in the environment)
#
# The sysroot is Debian bookworm for arm64 with the project's build dependencies, unpacked by
# `mmdebstrap --variant=extract` from this machine's own apt sources: nothing is configured or run, and the host's
# dpkg database is left alone (OpenCV's -dev packages are not multiarch co-installable, so a sysroot is the clean
# route). It is made once and reused while its package list (and this script's fix-ups) are unchanged: the key is
# stored in <sysroot>/.avatarbooth-sysroot-key. It is built under a temporary name and renamed when complete.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
sysroot="${1:-${ARM64_SYSROOT:-$root/build/arm64-sysroot}}"
suite=bookworm

# Host tools (also in tests/setup.sh's list, so CI installs them in one go with the rest).
host_packages=(g++-aarch64-linux-gnu qemu-user mmdebstrap)

# The arm64 build dependencies: the -dev packages tests/setup.sh installs natively, plus what they leave out because
# the host has it anyway (libc, libstdc++) or because only dlib's exported link line names it (jpeg, BLAS, LAPACK:
# dlib.cmake lists their unversioned .so files, which only the -dev packages ship). opencv-data: the cascades the
# unit tests may look up. No runtime-only packages (Mesa drivers, fonts, the 100 MB landmark model): the emulated
# subset is the unit label, which needs none of them.
sysroot_packages=(
  libc6-dev libstdc++-12-dev
  libopencv-dev opencv-data libdlib-dev libjpeg-dev libblas-dev liblapack-dev
  libtinygltf-dev nlohmann-json3-dev libglm-dev
  libegl-dev libgles-dev libopengl-dev libgbm-dev libdrm-dev libx11-dev
  libcli11-dev libspdlog-dev libtomlplusplus-dev libsystemd-dev libgpiod-dev libcamera-dev
  libfreetype-dev libpng-dev libexif-dev libstb-dev zlib1g-dev
  libqrencode-dev libcpp-httplib-dev libwebp-dev
  libcairo2-dev libcups2-dev libasound2-dev libvorbis-dev libsamplerate0-dev
  libgtest-dev libgmock-dev libbenchmark-dev
)

missing=()
for p in "${host_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "arm64 setup: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then echo "arm64 setup: run as root (apt-get needs it) or install: ${missing[*]}" >&2; exit 1; fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Bump fixups_version when the fix-ups below change, so that cached sysroots are remade.
fixups_version=1
key="$(printf '%s\n' "$suite" "fixups=$fixups_version" "${sysroot_packages[@]}" | sha256sum | cut -d' ' -f1)"
if [ -f "$sysroot/.avatarbooth-sysroot-key" ] && [ "$(cat "$sysroot/.avatarbooth-sysroot-key")" = "$key" ]; then
  echo "arm64 setup: sysroot $sysroot is up to date"
  exit 0
fi

# The machine's own apt sources (deb822 or one-line format), so the sysroot comes from the archive (or snapshot)
# the host installs from; mmdebstrap reads them as a file argument.
sources=""
for f in /etc/apt/sources.list.d/*.sources /etc/apt/sources.list; do
  [ -f "$f" ] && grep -qs 'debian' "$f" && { sources="$f"; break; }
done
if [ -z "$sources" ]; then echo "arm64 setup: no Debian apt sources found under /etc/apt" >&2; exit 1; fi

# root mode as root (CI); unshare mode (user namespaces) otherwise.
mode=root
[ "$(id -u)" -eq 0 ] || mode=unshare
tmp="$sysroot.partial"
rm -rf "$tmp"
mkdir -p "$(dirname "$sysroot")"
echo "arm64 setup: making the arm64 sysroot in $sysroot (mmdebstrap, $mode mode, sources $sources)"
start=$SECONDS
mmdebstrap --quiet --mode="$mode" --variant=extract --architectures=arm64 \
  --include="$(IFS=,; echo "${sysroot_packages[*]}")" "$suite" "$tmp" "$sources"

# Fix-ups for a tree that no maintainer script has run in:
# 1) absolute symlinks (libz.so -> /lib/aarch64-linux-gnu/libz.so.1...) would resolve on the host: make them
#    relative so they resolve inside the sysroot wherever it lives.
find "$tmp" -type l -lname '/*' -print0 | while IFS= read -r -d '' link; do
  target="$(readlink "$link")"
  ln -sfn "$(realpath -m --relative-to="$(dirname "$link")" "$tmp$target")" "$link"
done
libdir="$tmp/usr/lib/aarch64-linux-gnu"
# 2) the BLAS/LAPACK links update-alternatives would have made (OpenCV and dlib link and load them by these names).
for l in libblas.so libblas.so.3; do ln -sfn "blas/$l" "$libdir/$l"; done
for l in liblapack.so liblapack.so.3; do ln -sfn "lapack/$l" "$libdir/$l"; done
# 3) dlib's exported CMake and pkg-config files name /usr/lib/aarch64-linux-gnu/lib*.so literally: root them at the
#    file's own import prefix (CMake) and at pkg-config's sysroot (.pc), so the sysroot stays relocatable.
sed -i 's|"/usr/lib/aarch64-linux-gnu/lib|"${_IMPORT_PREFIX}/lib/aarch64-linux-gnu/lib|; s|;/usr/lib/aarch64-linux-gnu/lib|;${_IMPORT_PREFIX}/lib/aarch64-linux-gnu/lib|g' \
  "$libdir/cmake/dlib/dlib.cmake"
sed -i 's| /usr/lib/aarch64-linux-gnu/lib| ${pc_sysrootdir}/usr/lib/aarch64-linux-gnu/lib|g' "$libdir/pkgconfig/dlib-1.pc"
if grep -q '[" ;]/usr/lib/aarch64-linux-gnu/lib' "$libdir/cmake/dlib/dlib.cmake"; then
  echo "arm64 setup: dlib.cmake still names host paths" >&2; exit 1
fi
# The package caches are of no use to the build.
rm -rf "$tmp/var/cache/apt/archives/"*.deb "$tmp/var/lib/apt/lists/"*_Packages

echo "$key" >"$tmp/.avatarbooth-sysroot-key"
rm -rf "$sysroot"
mv "$tmp" "$sysroot"
echo "arm64 setup: sysroot ready in $((SECONDS - start)) s ($(du -sh "$sysroot" | cut -f1))"
