#!/bin/busybox sh
# /init of the kernel tests' initramfs: mounts the host's root (9p, read-only) and the work folder (9p,
# read-write), chroots into the host root and runs the guest script named on the kernel command line.
/bin/busybox mkdir -p /sbin /usr/bin /usr/sbin; /bin/busybox --install -s
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev
for a in $(cat /proc/cmdline); do
  case $a in gscript=*) GS=${a#gscript=};; wdir=*) WD=${a#wdir=};; kroot=*) KR=${a#kroot=};; keeptmp=*) KT=${a#keeptmp=};;
    groot=*) GR=${a#groot=};; gbind=*) GB=${a#gbind=};; esac
done
for m in $(cat /mods/order); do insmod /mods/$m; done
mount -t 9p -o trans=virtio,version=9p2000.L,ro,msize=512000,cache=loose hostroot /host
mount -t proc proc /host/proc; mount -t sysfs sys /host/sys; mount -t devtmpfs dev /host/dev
mount -t devpts devpts /host/dev/pts 2>/dev/null
# The guest's own /tmp; folders of the host's /tmp it needs (keeptmp: a checkout there) are bound back over it.
mkdir -p /hosttmp; mount -o bind /host/tmp /hosttmp
mount -t tmpfs tmp /host/tmp; mount -t tmpfs run /host/run
for d in $(echo "$KT" | tr , ' '); do mkdir -p "/host$d" && mount -o bind "/hosttmp${d#/tmp}" "/host$d"; done
mount -t debugfs debugfs /host/sys/kernel/debug 2>/dev/null
# The work folder may lie inside the read-only host root: mount it over its own path.
mount -t 9p -o trans=virtio,version=9p2000.L,msize=512000 work /host$WD
# Another release's root inside the host's (groot=, the trixie stage): its own /proc, /sys, /dev, /tmp and /run, the
# host folders it needs (gbind=) and the work folder bound in at their own paths.
R=/host
if [ -n "$GR" ]; then
  R=/host$GR
  mount -t proc proc $R/proc; mount -t sysfs sys $R/sys; mount -t devtmpfs dev $R/dev
  mount -t devpts devpts $R/dev/pts 2>/dev/null; mount -t tmpfs tmp $R/tmp; mount -t tmpfs run $R/run
  mount -t debugfs debugfs $R/sys/kernel/debug 2>/dev/null
  for d in $(echo "$GB" | tr , ' '); do mkdir -p "$R$d" 2>/dev/null; mount -o bind "/host$d" "$R$d"; done
  mount -o bind /host$WD $R$WD
fi
echo "[init] guest shell at uptime $(cut -d' ' -f1 /proc/uptime)s"
chroot $R /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root TERM=dumb W=$WD KMOD_ROOT=$KR \
  SYSTEMD_IGNORE_CHROOT=1 AVATARBOOTH_KERNEL_GUEST=1 /bin/bash -c "cd $WD && /bin/bash $GS"
rc=$?; echo $rc > /host$WD/rc
echo "[init] guest script exit code $rc at uptime $(cut -d' ' -f1 /proc/uptime)s"
umount /host$WD; sync; poweroff -f
