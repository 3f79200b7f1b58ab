#!/bin/sh
# /init of the HIL VM (busybox sh): mount the kernel's file systems, load
# the CAN modules, bring up vcan0, run /hil/run.sh (the scenario make hil
# put there), then write /out as a tar.gz onto the raw virtio disk the
# host gave (/dev/vda; its size on the console: "HIL-OUT-BYTES n"), and
# power off.  (Base64 on the serial console was tried first: a loaded host
# made the guest disable the UART's interrupt and the copy crawl.)
/bin/busybox --install -s /bin
export PATH=/bin:/hil
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mkdir -p /out /tmp
{
	echo "uname_v=$(uname -v)"
	echo "uname_r=$(uname -r)"
	echo "realtime=$(cat /sys/kernel/realtime 2>/dev/null || echo absent)"
} > /out/kernel.txt
cat /out/kernel.txt
ok=1
for m in can can-raw can-dev vcan; do
	insmod /lib/modules/$m.ko || { echo "hil-guest: insmod $m failed"; ok=0; }
done
ip link add dev vcan0 type vcan && ip link set vcan0 up || { echo "hil-guest: no vcan0"; ok=0; }
if [ $ok = 1 ]; then
	sh /hil/run.sh 2>&1 | tee /out/run.txt
else
	echo "setup failed" > /out/run.txt
fi
for m in virtio_ring virtio virtio_pci_modern_dev virtio_pci_legacy_dev virtio_pci virtio_blk; do
	insmod /lib/modules/$m.ko || echo "hil-guest: insmod $m failed"
done
n=0
while [ ! -b /dev/vda ] && [ $n -lt 50 ]; do sleep 0.1; n=$((n + 1)); done
tar -C /out -czf /tmp/out.tgz .
dd if=/tmp/out.tgz of=/dev/vda bs=64k conv=fsync 2>/dev/null &&
	echo "HIL-OUT-BYTES $(wc -c < /tmp/out.tgz)" || echo "hil-guest: no /dev/vda to write to"
sync
poweroff -f
