#!/usr/bin/env bash
# The main job: the built-in default scene (the paper's cuboid, top face
# touchable) from mesh to a verified image (cached: a second run reuses it
# while the scene and the tool are the same); its top-centre response
# exported and drawn; the force engine replays the paper's Fig. 6a step;
# then the controller, irdm-fw, runs the simulated PHANToM-like board with a
# virtual hand that presses the top centre, holds and lets go, in virtual
# time, and its log is exported and drawn, with a frame of the deformed
# surface mid-hold (t = 1.5 s, the deformation worker's VTK).
#   tools/scripts/run-default-scene.sh [IRDM] [IRDM_FW]   -> out/default.*, out/run*
set -euo pipefail
irdm=${1:-build/irdm}
fw=${2:-build/irdm-fw}
py=/usr/bin/python3
tools/scripts/default-image.sh "$irdm"
"$irdm" image verify out/default.img
"$irdm" image info out/default.img | head -n 14
# node 3246 = grid (6, 6, 22): the top face, next to its centre
"$irdm" image export out/default.img --column 3246 --samples 2000 -o out/default-response.csv
awk 'BEGIN { print "t,ux,uy,uz"; for (i = 0; i < 3000; i++) printf "%.3f,0,0,%s\n", i * 0.001, (i < 10 ? -0.001 * (i + 1) : -0.01) }' \
	> out/default-step.csv
"$irdm" replay --image out/default.img --contact 3246 --displacement out/default-step.csv \
	-o out/default-forces.csv --nodes 3246
tail -n 1 out/default-forces.csv | awk -F, '{ printf "replay: force on the object after 3 s: (%.4f, %.4f, %.4f) N\n", $2, $3, $4 }'

echo "run: irdm-fw on boards/sim-phantom.board, scenes/users/press-hold-release.user, virtual time"
"$fw" --board boards/sim-phantom.board --image out/default.img \
	--user scenes/users/press-hold-release.user --clock virtual --log out/run.log \
	--frame-at 1.5 --frame-out out/run-frame.vtk --frames-every 0.1 --frames-out out/run-frames
"$irdm" log export out/run.log -o out/run.csv
echo "run: to watch this run in the browser (docs/view.md), serve it and open http://127.0.0.1:8080/:"
echo "  $irdm view out/run.log --board boards/sim-phantom.board --image out/default.img"

if $py -c 'import matplotlib' 2>/dev/null; then
	$py tools/scripts/plot-response.py out/default-response.csv out/default-response.png
	$py tools/scripts/plot-forces.py out/default-forces.csv out/default-forces.png \
		"paper's cuboid, top node pushed 1 cm in 10 ms and held (Fig. 6a)"
	$py tools/scripts/plot-log.py out/run.csv out/run \
		"irdm-fw, simulated PHANToM: press the top centre, hold 2 s, release"
	$py tools/scripts/plot-surface.py out/run-frame.vtk out/run-frame.png \
		"irdm-fw, simulated PHANToM: the deformed surface mid-hold"
	# frame N is at N x 0.1 s: pressing in (1.1 s), the hold's start and
	# end (1.3 s, 3.0 s), ringing 0.1 s after the release at 3.2 s (3.3 s)
	$py tools/scripts/plot-surface.py out/run-frames/frame_000{11,13,30,33}.vtk \
		out/run-frames.png "irdm-fw: press, hold, release"
	echo "run: plots out/default-response.png out/default-forces.png out/run-force.png out/run-latency.png out/run-compute.png out/run-frame.png out/run-frames.png"
else
	echo "run: python3-matplotlib not installed; skipped the PNG plots"
fi
