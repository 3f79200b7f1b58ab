#!/usr/bin/env bash
# The main job: the built-in default scene (the paper's cuboid, top face
# touchable) from mesh to a verified image; its top-centre response exported
# and drawn; then the force engine replays the paper's Fig. 6a step (the top
# node pushed 1 cm and held for 3 s) and the force curve is drawn.
#   tools/scripts/run-default-scene.sh [IRDM]   -> out/default.*
set -euo pipefail
irdm=${1:-build/irdm}
mkdir -p out
"$irdm" precompute --scene scenes/cuboid-top.scene -o out/default.img
"$irdm" image verify out/default.img
"$irdm" image info out/default.img | head -n 14
# node 3246 = grid (6, 6, 22): the top face, next to its centre
"$irdm" image export out/default.img --column 3246 --samples 2000 -o out/default-response.csv
awk 'BEGIN { print "t,ux,uy,uz"; for (i = 0; i < 3000; i++) printf "%.3f,0,0,%s\n", i * 0.001, (i < 10 ? -0.001 * (i + 1) : -0.01) }' \
	> out/default-step.csv
"$irdm" replay --image out/default.img --contact 3246 --displacement out/default-step.csv \
	-o out/default-forces.csv --nodes 3246
tail -n 1 out/default-forces.csv | awk -F, '{ printf "replay: force on the object after 3 s: (%.4f, %.4f, %.4f) N\n", $2, $3, $4 }'
if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
	/usr/bin/python3 tools/scripts/plot-response.py out/default-response.csv out/default-response.png
	/usr/bin/python3 tools/scripts/plot-forces.py out/default-forces.csv out/default-forces.png \
		"paper's cuboid, top node pushed 1 cm in 10 ms and held (Fig. 6a)"
else
	echo "run: python3-matplotlib not installed; skipped the PNG plots"
fi
