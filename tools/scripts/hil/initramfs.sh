#!/usr/bin/env bash
# The HIL VM's initramfs: busybox (static), /init, the CAN modules, and
# every file of STAGE (binaries, boards, scripts, images) under /hil, with
# the shared libraries each dynamic binary there needs (ldd) at their host
# paths.  Output: a gzip'd newc cpio.
#   tools/scripts/hil/initramfs.sh OUT.cpio.gz KERNEL_DIR STAGE_DIR
set -euo pipefail
out=$1 kdir=$2 stage=$3
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
mkdir -p "$root"/{bin,proc,sys,dev,lib/modules,hil}
cp /bin/busybox "$root/bin/busybox"
ln -s busybox "$root/bin/sh"
cp "$(dirname "$0")/guest-init.sh" "$root/init"
chmod +x "$root/init"
cp "$kdir"/modules/*.ko "$root/lib/modules/"
cp -r "$stage"/. "$root/hil/"
for f in "$root"/hil/*; do
	[ -f "$f" ] && [ -x "$f" ] && file -b "$f" | grep -q 'dynamically linked' || continue
	ldd "$f" | awk '/=> \// { print $3 } /^\t\/lib/ { print $1 }' | while read -r lib; do
		mkdir -p "$root$(dirname "$lib")"
		cp -L "$lib" "$root$lib"
	done
done
# the loader's canonical path
[ -e "$root/lib64/ld-linux-x86-64.so.2" ] || { mkdir -p "$root/lib64"; cp -L /lib64/ld-linux-x86-64.so.2 "$root/lib64/"; }
(cd "$root" && find . | busybox cpio -o -H newc 2>/dev/null) | gzip -1 > "$out.tmp"
mv "$out.tmp" "$out"
echo "hil: initramfs $out ($(du -k "$out" | cut -f1) kB)"
