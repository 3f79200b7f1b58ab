#!/usr/bin/env bash
# The default scene's image (the paper's cuboid, top face touchable) in
# out/default.img, verified; cached: reused while the scene and the tool
# are the same (make run and make render share it).  The tool is keyed by
# its binary, not its version string: a precompute change that keeps the
# version must not leave an image it would no longer write.
#   tools/scripts/default-image.sh [IRDM]
set -euo pipefail
irdm=${1:-build/irdm}
mkdir -p out
key="$(sha256sum scenes/cuboid-top.scene | cut -c1-16) $("$irdm" --version) $(sha256sum "$irdm" | cut -c1-16)"
if [ -f out/default.img ] && [ "$(cat out/default.img.key 2>/dev/null)" = "$key" ] &&
	"$irdm" image verify out/default.img >/dev/null 2>&1; then
	echo "out/default.img is up to date (scene and tool unchanged): precompute skipped"
else
	"$irdm" precompute --scene scenes/cuboid-top.scene -o out/default.img
	echo "$key" > out/default.img.key
fi
