#!/usr/bin/env bash
# The PREEMPT_RT kernel the HIL VM boots, from Debian's own package
# (linux-image-rt-amd64 -> its versioned package), unpacked without dpkg
# (no hooks run) into DIR and cached there: DIR/vmlinux (the uncompressed
# kernel, booted through its PVH entry: about 2.5 s faster under TCG than
# the bzImage's decompressor), DIR/VERSION and DIR/modules/ (the .ko files
# make hil loads: CAN and vcan; virtio-blk for the results disk; each
# after its dependencies, which their .modinfo lists).
#   tools/scripts/hil/kernel.sh DIR
set -euo pipefail
dir=$1
mkdir -p "$dir"
pkg=$(apt-cache depends linux-image-rt-amd64 | sed -n 's/^ *Depends: \(linux-image-[0-9].*-rt-amd64\)$/\1/p' | head -n 1)
if [ -z "$pkg" ]; then
	echo "hil: apt-cache knows no linux-image-rt-amd64 (apt-get update?)" >&2
	exit 1
fi
if [ -f "$dir/vmlinux" ] && [ "$(cat "$dir/PACKAGE" 2>/dev/null)" = "$pkg" ] &&
	[ -f "$dir/modules/virtio_blk.ko" ]; then
	echo "hil: kernel $pkg cached in $dir"
	exit 0
fi
echo "hil: fetching $pkg"
rm -rf "$dir/deb" "$dir/x" "$dir/modules"
mkdir -p "$dir/deb"
(cd "$dir/deb" && apt-get download -q "$pkg" 2>&1 | grep -v '^W: Download is performed unsandboxed' || true)
deb=$(ls "$dir"/deb/*.deb)
dpkg-deb -x "$deb" "$dir/x"
version=$(ls "$dir/x/lib/modules")
# the xz payload inside the bzImage: from its magic, one stream
bz="$dir/x/boot/vmlinuz-$version"
off=$(grep -abo $'\xfd7zXZ\x00' "$bz" | head -n 1 | cut -d: -f1)
xz -dc --single-stream < <(tail -c +"$((off + 1))" "$bz" 2>/dev/null || true) > "$dir/vmlinux.tmp"
mv "$dir/vmlinux.tmp" "$dir/vmlinux"
mkdir -p "$dir/modules"
for m in can can-raw can-dev vcan virtio_ring virtio virtio_pci_modern_dev virtio_pci_legacy_dev \
	virtio_pci virtio_blk; do
	find "$dir/x/lib/modules/$version" -name "$m.ko" -exec cp {} "$dir/modules/" \;
	[ -f "$dir/modules/$m.ko" ] || { echo "hil: $pkg has no $m.ko" >&2; exit 1; }
done
echo "$version" > "$dir/VERSION"
rm -rf "$dir/x" "$dir/deb"
echo "$pkg" > "$dir/PACKAGE"
echo "hil: kernel $version unpacked into $dir"
