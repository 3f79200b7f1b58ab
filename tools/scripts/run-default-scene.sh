#!/usr/bin/env bash
# The main job, until the force loop lands: the built-in default scene (the
# paper's cuboid, top face touchable) from mesh to a verified image, its
# top-centre response exported as CSV and drawn as PNG.
#   tools/scripts/run-default-scene.sh [IRDM]   -> out/default.*
set -euo pipefail
irdm=${1:-build/irdm}
mkdir -p out
"$irdm" precompute --scene scenes/cuboid-top.scene -o out/default.img
"$irdm" image verify out/default.img
"$irdm" image info out/default.img | head -n 14
# node 3246 = grid (6, 6, 22): the top face, next to its centre
"$irdm" image export out/default.img --column 3246 --samples 2000 -o out/default-response.csv
if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
	/usr/bin/python3 tools/scripts/plot-response.py out/default-response.csv out/default-response.png
else
	echo "run: python3-matplotlib not installed; skipped out/default-response.png"
fi
