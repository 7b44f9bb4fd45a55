#!/usr/bin/env bash
# Prepares the qemu guest for the `kernel` tests: Debian's stock kernel, its vivid and virtio-gpu modules,
# vimc/gpio-sim/irq_sim/vkms built out of tree from linux-source-6.1, a pruned module tree and a busybox initramfs.
# Cached per kernel version.
# Usage: tests/kernel/setup.sh CACHE_DIR   -> prints CACHE_DIR/<kernel version> (holds vmlinuz, initrd.img, kroot/)
# Needs root for apt-get when packages are missing; ~2-3 min the first time, nothing once cached (~20 MB kept).
set -euo pipefail
cache=$(readlink -m "${1:?usage: setup.sh CACHE_DIR}")
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

# Host tools the guest runs from the shared root (qemu itself, udevd for libcamera, the IPA modules) and what the
# module build needs. Installed here so that `ctest -L kernel` works on its own; tests/setup.sh lists them too.
packages=(qemu-system-x86 busybox-static cpio kmod xz-utils make gcc-12 libc6-dev v4l-utils libcamera-tools
          libcamera-ipa udev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
export DEBIAN_FRONTEND=noninteractive
apt_updated=0
if ((${#missing[@]})); then
  [ "$(id -u)" -eq 0 ] || { echo "kernel setup: run as root or install: ${missing[*]}" >&2; exit 1; }
  apt-get -o DPkg::Lock::Timeout=900 update -qq; apt_updated=1
  apt-get -o DPkg::Lock::Timeout=900 install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

# The kernel Debian's linux-image-amd64 points at (the guest runs the distribution's own kernel, not the host's).
PKG=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-6/{print $2; exit}')
if [ -z "$PKG" ] && [ "$apt_updated" = 0 ] && [ "$(id -u)" -eq 0 ]; then
  apt-get -o DPkg::Lock::Timeout=900 update -qq; apt_updated=1
  PKG=$(apt-cache depends linux-image-amd64 | awk '/Depends: linux-image-6/{print $2; exit}')
fi
[ -n "$PKG" ] || { echo "kernel setup: apt knows no linux-image-amd64 (run apt-get update)" >&2; exit 1; }
KV=${PKG#linux-image-}; FLAV=${KV##*-}; ABI=${KV%-"$FLAV"}     # 6.1.0-NN-amd64 / amd64 / 6.1.0-NN
W=$cache/$KV
# The cache key includes this script and the guest's init: a change to either rebuilds.
stamp=$(cat "$0" "$here/guest_init.sh" | sha256sum | cut -c1-16)
if [ -f "$W/ready" ] && [ "$(cat "$W/ready")" = "$stamp" ]; then echo "$W"; exit 0; fi

echo "kernel setup: preparing $KV in $W" >&2
rm -rf "$W"; mkdir -p "$W"/{dl,hdr,ext/vimc,ext/gpio,ext/vkms,initrd/{bin,dev,proc,sys,host,mods}}
cd "$W/dl"
VER=$(apt-cache policy "$PKG" | awk '/Candidate:/{print $2}')
apt-get download "$PKG" "linux-headers-$KV" "linux-headers-$ABI-common" "linux-kbuild-6.1=$VER" \
  "linux-source-6.1=$VER" >&2
dpkg -x "${PKG}"_*.deb img
for f in linux-headers-*.deb linux-kbuild-*.deb; do dpkg -x "$f" "$W/hdr"; done
H=$W/hdr/usr/src/linux-headers-$KV
sed -i "s#^include /usr/src/#include $W/hdr/usr/src/#" "$H/Makefile"   # the headers are not under /usr/src
cp img/boot/vmlinuz-"$KV" "$W/vmlinuz"
# Only the driver sources we need from the 140 MB source tarball.
dpkg-deb --fsys-tarfile linux-source-6.1_*.deb | tar -xO ./usr/src/linux-source-6.1.tar.xz |
  tar -xJ --strip-components=1 -C "$W/ext" --wildcards 'linux-source-6.1/drivers/media/test-drivers/vimc/*.[ch]' \
    'linux-source-6.1/drivers/gpio/gpio-sim.c' 'linux-source-6.1/drivers/gpio/gpiolib.h' \
    'linux-source-6.1/kernel/irq/irq_sim.c' 'linux-source-6.1/drivers/gpu/drm/vkms/*.[ch]'
cp "$W"/ext/drivers/media/test-drivers/vimc/*.[ch] "$W/ext/vimc/"
cp "$W"/ext/drivers/gpio/{gpio-sim.c,gpiolib.h} "$W"/ext/kernel/irq/irq_sim.c "$W/ext/gpio/"
cp "$W"/ext/drivers/gpu/drm/vkms/*.[ch] "$W/ext/vkms/"
printf 'obj-m := vimc.o\nvimc-y := vimc-core.o vimc-common.o vimc-streamer.o vimc-capture.o vimc-debayer.o vimc-scaler.o vimc-sensor.o vimc-lens.o\n' \
  > "$W/ext/vimc/Kbuild"
# Debian's kernel lacks CONFIG_IRQ_SIM: irq_sim.c becomes its own module. irq_to_desc() is not exported to
# modules; generic_handle_irq() does the same here (the descriptor's handler is handle_simple_irq).
sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$W/ext/gpio/irq_sim.c"
grep -q 'generic_handle_irq(irqnum)' "$W/ext/gpio/irq_sim.c" || { echo "kernel setup: irq_sim.c patch did not apply" >&2; exit 1; }
echo 'MODULE_LICENSE("GPL");' >> "$W/ext/gpio/irq_sim.c"
echo 'obj-m := irq_sim.o gpio-sim.o' > "$W/ext/gpio/Kbuild"
# vkms (the virtual KMS screen, with a writeback connector): CONFIG_DRM_VKMS is off in Debian's kernel; what it
# uses (drm, drm_kms_helper, drm_shmem_helper) is built as modules there.
# vkms on 6.1 leaves its encoders' possible_clones empty, which the DRM core turns into "only itself": the writeback
# connector then cannot share the CRTC with the Virtual-1 screen (drm_atomic_check_valid_clones: EINVAL) and can only
# capture a CRTC that drives nothing else. The two encoders are made clones of each other, so that the writeback
# reads back the very frames the screen is shown.
sed -i 's|DRM_ERROR("Failed to init writeback connector\\n");|&\n\t\telse\n\t\t\tencoder->possible_clones = output->wb_connector.encoder.possible_clones =\n\t\t\t\tdrm_encoder_mask(encoder) \| drm_encoder_mask(\&output->wb_connector.encoder);|' \
  "$W/ext/vkms/vkms_output.c"
grep -q 'possible_clones = output->wb_connector' "$W/ext/vkms/vkms_output.c" || { echo "kernel setup: vkms_output.c patch did not apply" >&2; exit 1; }
printf 'obj-m := vkms.o\nvkms-y := vkms_drv.o vkms_plane.o vkms_output.o vkms_formats.o vkms_crtc.o vkms_composer.o vkms_writeback.o\n' \
  > "$W/ext/vkms/Kbuild"
make -s -C "$H" M="$W/ext/vimc" -j"$(nproc)" modules >&2
make -s -C "$H" M="$W/ext/gpio" -j"$(nproc)" modules >&2
make -s -C "$H" M="$W/ext/vkms" -j"$(nproc)" modules >&2
mkdir -p img/lib/modules/"$KV"/extra && cp "$W"/ext/{vimc,gpio,vkms}/*.ko img/lib/modules/"$KV"/extra/
depmod -b "$W/dl/img" "$KV"
# A pruned module tree for the guest (a few MB instead of 400 MB).
R=$W/kroot/lib/modules/$KV; mkdir -p "$R"
for m in vivid vimc gpio-sim vkms virtio-gpu configfs; do
  modprobe -d "$W/dl/img" -S "$KV" --show-depends $m | awk '$1 == "insmod" {print $2}'
done | sort -u | while read -r f; do
  rel=${f#*/lib/modules/$KV/}; mkdir -p "$R/$(dirname "$rel")"; cp "$f" "$R/$rel"
done
cp img/lib/modules/"$KV"/modules.{order,builtin,builtin.modinfo} "$R/"; depmod -b "$W/kroot" "$KV"
# The initramfs: static busybox, virtio-pci + 9p modules, /init.
cp /bin/busybox "$W/initrd/bin/"
for m in virtio_pci 9pnet_virtio 9p; do
  modprobe -d "$W/dl/img" -S "$KV" --show-depends $m | awk '$1 == "insmod" {print $2}'
done | awk '!s[$0]++' | while read -r f; do cp "$f" "$W/initrd/mods/"; basename "$f"; done > "$W/initrd/mods/order"
cp "$here/guest_init.sh" "$W/initrd/init"; chmod +x "$W/initrd/init"
(cd "$W/initrd" && find . | cpio -o -H newc --quiet | gzip -1 > "$W/initrd.img")
rm -rf "$W/dl" "$W/ext" "$W/hdr" "$W/initrd"
echo "$stamp" > "$W/ready"
du -sh "$W" >&2
echo "$W"
