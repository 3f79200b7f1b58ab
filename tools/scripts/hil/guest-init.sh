#!/bin/sh
# /init of the HIL VM (busybox sh): mount the kernel's file systems, load
# the CAN modules, bring up vcan0, run /hil/run.sh (the scenario make hil
# put there), then send /out back over the serial console as a base64 tar
# between two marker lines, and power off.  Nothing here may hang: the
# host's timeout would then be the only way out, so every step is bounded.
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
echo "HIL-OUT-BEGIN"
tar -C /out -czf - . | base64
echo "HIL-OUT-END"
sync
poweroff -f
